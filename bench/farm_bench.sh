#!/usr/bin/env bash
# Build farm figures (docs/BENCHMARKS.md, "Build farm"): the sample scene baked in one process
# (--threads 2) and through Slurm (a one-node cluster, tests/farm/local_cluster.sh; 2 shards of
# 1 CPU at once, the plan job on 2), wall times as medians of RUNS alternating rounds; then the same steps by hand
# with --json for what the farm's time is made of, and the per-core rates the 128K model uses
# (bench/farm_model.py). Run as root, through `heavy`.
#   bench/farm_bench.sh VTBAKE [SIZE_PAGES=16] [RUNS=3] [BAKE FLAGS...]   (e.g. --codec bc:high)
# Environment: FARM_SCENE=PATH bakes that scene instead of the sample (e.g. VirtualCity for the
# 64K figure, with --memory-limit 2G); FARM_BY_HAND=0 skips the steps by hand and the model;
# FARM_TIME sets the Slurm jobs' time limit (default 1:00:00); FARM_WORK_RATIO is the model's
# raw-floats-to-work-folder ratio (bench/farm_model.py --work-ratio). After each farm round it prints
# when the plan, each part and the merged file were written (seconds from the start).
set -euo pipefail
vtbake=$(readlink -f "$1")
size="${2:-16}"
runs="${3:-3}"
shift $(($# < 3 ? $# : 3))
src=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d /tmp/vtbake-farm-bench.XXXXXX)
source "$src/tests/farm/local_cluster.sh"
trap 'stop_cluster; [[ -n "${VTBAKE_KEEP_BENCH:-}" ]] || rm -rf "$tmp"' EXIT
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
scene="${FARM_SCENE:-}"
if [[ -z "$scene" ]]; then
  "$vtbake" -q sample-scene "$tmp/scene"
  scene="$tmp/scene/scene.gltf"
fi
flags=(--size "$size" "$@")
now() { date +%s.%N; }
median() { sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }

mkdir -p "$tmp/local"
# The farm's steps log their --json reports (stage times) under the work folder's logs/; farm.sh's
# own `merge --missing` query (read line by line, to resubmit shards) keeps its plain output.
printf '#!/bin/sh\ncase " $* " in *" --missing "*) exec %q "$@" ;; esac\nexec %q --json "$@"\n' \
  "$vtbake" "$vtbake" >"$tmp/vtbake-json"
chmod +x "$tmp/vtbake-json"
start_cluster "$tmp/cluster"
# Alternating rounds (one process, then the farm), so both see the same load.
: >"$tmp/local.times"
: >"$tmp/farm.times"
for r in $(seq "$runs"); do
  t0=$(now)
  "$vtbake" --json --threads 2 bake "$scene" -o "$tmp/local/out.vtpf" "${flags[@]}" >"$tmp/local-$r.json"
  echo "$(now) - $t0" | bc >>"$tmp/local.times"
  rm -rf "$tmp/farm"
  t0=$(now)
  PATH="$(dirname "$vtbake"):$PATH" "$src/scripts/farm.sh" --work "$tmp/farm/work" --shards 2 \
    --cpus 1 --plan-cpus 2 --poll 0.2 --time "${FARM_TIME:-1:00:00}" --vtbake "$tmp/vtbake-json" \
    -- "$scene" -o "$tmp/farm/out.vtpf" "${flags[@]}" >/dev/null
  echo "$(now) - $t0" | bc >>"$tmp/farm.times"
  cmp "$tmp/local/out.vtpf" "$tmp/farm/out.vtpf"
  for f in "$tmp/farm/work/plan.json" "$tmp"/farm/work/parts/*.part "$tmp/farm/out.vtpf"; do
    echo "  round $r: $(basename "$f") written at +$(echo "$(date -r "$f" +%s.%N) - $t0" | bc) s"
  done
  cp -r "$tmp/farm/work/logs" "$tmp/logs-$r"
  echo "  round $r: work folder $(du -sb "$tmp/farm/work" | cut -f1) bytes, $(du -sB1 "$tmp/farm/work" | cut -f1) on disk"
done
echo "one process (--threads 2): median $(median <"$tmp/local.times") s of $(paste -sd' ' "$tmp/local.times")"
echo "Slurm, 2 shards x 1 CPU: median $(median <"$tmp/farm.times") s of $(paste -sd' ' "$tmp/farm.times") (merged file byte-identical)"
stop_cluster
if [[ "${FARM_BY_HAND:-1}" == 0 ]]; then
  echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
  exit 0
fi

# The steps by hand, with their stage times.
w="$tmp/hand/work"
mkdir -p "$tmp/hand"
b=(bake "$scene" -o "$tmp/hand/out.vtpf" "${flags[@]}" --work "$w")
t0=$(now)
"$vtbake" --json --threads 2 "${b[@]}" --plan "$w/plan.json" >"$tmp/plan.json.out"
t1=$(now)
"$vtbake" --json --threads 1 "${b[@]}" --shard 0/2 >"$tmp/shard0.json" &
"$vtbake" --json --threads 1 "${b[@]}" --shard 1/2 >"$tmp/shard1.json"
wait
t2=$(now)
"$vtbake" --json merge "$w" -o "$tmp/hand/out.vtpf" >"$tmp/merge.json"
t3=$(now)
cmp "$tmp/local/out.vtpf" "$tmp/hand/out.vtpf"
echo "by hand: plan $(echo "$t1 - $t0" | bc) s, 2 shards at once $(echo "$t2 - $t1" | bc) s, merge $(echo "$t3 - $t2" | bc) s"
# Per-core rates: one shard of one (every page) and the plan's key pass, at 1 thread.
"$vtbake" --json --threads 1 "${b[@]}" --shard 0/1 >"$tmp/shard_all.json"
mkdir -p "$tmp/hand1"
"$vtbake" --json --threads 1 bake "$scene" -o "$tmp/hand1/out.vtpf" "${flags[@]}" \
  --work "$tmp/hand1/work" --plan "$tmp/hand1/work/plan.json" >"$tmp/plan1.json.out"
python3 "$src/bench/farm_model.py" --plan "$tmp/plan.json.out" --plan1 "$tmp/plan1.json.out" \
  --plan-graph "$w/plan.json" --shards "$tmp/shard0.json" "$tmp/shard1.json" \
  --shard-all "$tmp/shard_all.json" --merge "$tmp/merge.json" --work-ratio "${FARM_WORK_RATIO:-1}"
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
