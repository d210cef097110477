#!/usr/bin/env bash
# The engine-hook figures of docs/BENCHMARKS.md (issue 18): the embedding example at 1080p with
# the library's threads and with its own job pool (the job hook), one and two virtual textures
# in one feedback buffer, in interleaved rounds; prints one line per run, then the medians.
#   bench/embed_hooks_bench.sh [--example build/release/tests/package/vt_embed_example]
#                              [--rounds 3] FILE.vtpf...
set -euo pipefail
example=build/release/tests/package/vt_embed_example
rounds=3
files=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --example) example="$2"; shift 2 ;;
    --rounds) rounds="$2"; shift 2 ;;
    *) files+=("$1"); shift ;;
  esac
done
[[ ${#files[@]} -gt 0 ]] || { echo "usage: $0 [--example PATH] [--rounds N] FILE.vtpf..." >&2; exit 2; }
[[ -x "$example" ]] || { echo "$0: no example at $example (build first)" >&2; exit 2; }
log=$(mktemp)
trap 'rm -f "$log"' EXIT
for ((round = 1; round <= rounds; ++round)); do
  for f in "${files[@]}"; do
    for mode in "" "--jobs 2" "--textures 2" "--textures 2 --jobs 2"; do
      echo "round $round file $(basename "$f") mode [$mode] load $(cut -d' ' -f1 /proc/loadavg)" | tee -a "$log"
      # shellcheck disable=SC2086
      "$example" "$f" --frames 120 --quiet $mode | tail -2 | tee -a "$log"
    done
  done
done
python3 - "$log" <<'PY'
import re, statistics as st, sys
rows, cur = {}, None
for line in open(sys.argv[1]):
    m = re.match(r'round \d+ file (\S+) mode \[(.*)\] load (\S+)', line)
    if m:
        cur = (m[1], m[2] or 'library threads')
        rows.setdefault(cur, {'open': [], 'first': [], 'mean': [], 'max': [], 'load': []})['load'].append(float(m[3]))
        continue
    m = re.match(r'vtrt_open (\S+) ms, first requested page uploaded (\S+) ms', line)
    if m:
        rows[cur]['open'].append(float(m[1])); rows[cur]['first'].append(float(m[2])); continue
    m = re.match(r'vtrt_update: (\S+) ms per frame on average, (\S+) ms at most; (\d+)', line)
    if m:
        rows[cur]['mean'].append(float(m[1])); rows[cur]['max'].append(float(m[2])); rows[cur]['uploads'] = m[3]
print('| file | mode | vtrt_open ms | first page ms | vtrt_update mean ms | max ms | uploads | load |')
print('|---|---|---:|---:|---:|---:|---:|---|')
for (f, mode), v in rows.items():
    print(f"| {f} | {mode} | {st.median(v['open']):.1f} | {st.median(v['first']):.0f} | "
          f"{st.median(v['mean']):.2f} ({min(v['mean']):.2f}-{max(v['mean']):.2f}) | "
          f"{st.median(v['max']):.1f} | {v['uploads']} | {min(v['load'])}-{max(v['load'])} |")
PY
