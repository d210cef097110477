#!/usr/bin/env bash
# Runs every fuzz target of a `fuzz` preset build for a bounded time each and fails on any finding.
#   fuzz/run.sh [--build DIR] [--seconds N] [--jobs J] [--only TARGET] [--corpus DIR]
# Corpora start from the seeds the build wrote (DIR/fuzz/seeds) and grow in --corpus (default
# DIR/fuzz/corpus, kept between runs). A finding's input lands in DIR/fuzz/findings/; the run
# prints one line per target (executions, exec/s, cov, ft, corpus size) and exits non-zero if
# any target found something. J targets run at once (default 1).
set -uo pipefail
cd "$(dirname "$0")/.."
build=build/fuzz seconds=25 jobs=1 only="" corpus=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build) build=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --only) only=$2; shift 2 ;;
    --corpus) corpus=$2; shift 2 ;;
    *) echo "fuzz/run.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
bin=$build/fuzz
corpus=${corpus:-$bin/corpus}
findings=$bin/findings
logs=$bin/logs
mkdir -p "$corpus" "$findings" "$logs"

# target, seed folder, dictionary, longest input (a DCT layer's tables are about 30 KB)
targets=(
  "page_file page_file vtpf.dict 262144"
  "page_file_c page_file vtpf.dict 262144"
  "dct dct - 65536"
  "gltf gltf gltf.dict 65536"
  "obj obj obj.dict 65536"
  "ply ply ply.dict 65536"
  "ac3d ac3d ac3d.dict 65536"
  "pcx pcx - 65536"
  "iqm iqm - 65536"
)

run_one() {
  local name=$1 seeds=$2 dict=$3 max_len=$4
  local out=$corpus/$name log=$logs/$name.log
  mkdir -p "$out"
  local args=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=1024
              -max_len="$max_len" -print_final_stats=1 -artifact_prefix="$findings/$name-")
  [[ $dict != - ]] && args+=(-dict="fuzz/$dict")
  ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1} \
  UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1} \
    "$bin/vt_fuzz_$name" "${args[@]}" "$out" "$bin/seeds/$seeds" >"$log" 2>&1
  local rc=$?
  local runs rate rss cov ft
  stat() { awk -v k="stat::$1:" '$1 == k { v = $2 } END { print v }' "$log"; }
  runs=$(stat number_of_executed_units)
  rate=$(stat average_exec_per_sec)
  rss=$(stat peak_rss_mb)
  cov=$(grep -oE 'cov: [0-9]+' "$log" | tail -1 | grep -oE '[0-9]+')
  ft=$(grep -oE 'ft: [0-9]+' "$log" | tail -1 | grep -oE '[0-9]+')
  local files
  files=$(find "$out" -type f | wc -l)
  printf '%-12s rc=%d runs=%s exec/s=%s cov=%s ft=%s corpus=%s rss_mb=%s\n' "$name" "$rc" \
    "${runs:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" "$files" "${rss:-?}"
  if [[ $rc -ne 0 ]]; then
    echo "fuzz: $name found something (log: $log):" >&2
    grep -E 'ERROR|fuzz finding|SUMMARY|runtime error|Test unit written' "$log" | head -20 >&2
  fi
  return $rc
}

failed=0
pids=()
for t in "${targets[@]}"; do
  read -r name seeds dict max_len <<<"$t"
  [[ -n $only && $only != "$name" ]] && continue
  run_one "$name" "$seeds" "$dict" "$max_len" &
  pids+=($!)
  if [[ ${#pids[@]} -ge $jobs ]]; then
    wait "${pids[0]}" || failed=1
    pids=("${pids[@]:1}")
  fi
done
for p in "${pids[@]}"; do wait "$p" || failed=1; done
exit $failed
