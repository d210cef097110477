#!/usr/bin/env bash
# Start-up of the vtbake page-file commands (issue 22): per-command wall medians and a batch of
# small jobs (info, verify, extract in turn on one small page file), for one or more vtbake
# binaries side by side, interleaved so that load changes hit every candidate alike.
#
#   bench/startup_bench.sh [-n JOBS] [-r RUNS] VTBAKE [VTBAKE...]
#
# A candidate is a vtbake executable (e.g. build/release/cli/vtbake and a copy of an older
# build). Prints the load average with every figure: on a busy machine, say so.
set -euo pipefail

jobs=1000
runs=50
while getopts "n:r:" opt; do
  case $opt in
    n) jobs=$OPTARG ;;
    r) runs=$OPTARG ;;
    *) exit 2 ;;
  esac
done
shift $((OPTIND - 1))
[ $# -ge 1 ] || { echo "usage: $0 [-n JOBS] [-r RUNS] VTBAKE [VTBAKE...]" >&2; exit 2; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
page_file=$work/small.vtpf
"$1" -q build procedural:256x256 -o "$page_file"
echo "page file: $(stat -c %s "$page_file") bytes (procedural:256x256, 3 levels, 14 pages)"

command_args() {  # the job's arguments, by kind
  case $1 in
    info) echo "info $page_file" ;;
    verify) echo "verify $page_file" ;;
    extract) echo "-q extract $page_file --level 1 -o $work/level1.png" ;;
  esac
}

now_ns() { date +%s%N; }
median() { sort -n | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }

echo "== start-up: median wall of $runs runs, ms (load: $(cut -d' ' -f1-3 /proc/loadavg))"
for kind in info verify extract; do
  read -r -a args <<< "$(command_args $kind)"
  for i in $(seq 0 $(($# - 1))); do : > "$work/t$i"; done
  for _ in $(seq "$runs"); do
    i=0
    for bin in "$@"; do
      t0=$(now_ns)
      "$bin" "${args[@]}" > /dev/null
      echo $((($(now_ns) - t0) / 1000)) >> "$work/t$i"
      i=$((i + 1))
    done
  done
  i=0
  for bin in "$@"; do
    printf '%-8s %-50s %8.1f ms\n' "$kind" "$bin" "$(median < "$work/t$i" | awk '{print $1 / 1000}')"
    i=$((i + 1))
  done
done

# The batch: $jobs jobs per candidate, run in interleaved chunks of 100.
echo "== batch of $jobs small jobs (info, verify, extract in turn), total wall s (load before: $(cut -d' ' -f1-3 /proc/loadavg))"
kinds=(info verify extract)
i=0
for bin in "$@"; do echo 0 > "$work/b$i"; i=$((i + 1)); done
done_jobs=0
while [ "$done_jobs" -lt "$jobs" ]; do
  chunk=$((jobs - done_jobs < 100 ? jobs - done_jobs : 100))
  i=0
  for bin in "$@"; do
    t0=$(now_ns)
    for j in $(seq "$done_jobs" $((done_jobs + chunk - 1))); do
      read -r -a args <<< "$(command_args ${kinds[$((j % 3))]})"
      "$bin" "${args[@]}" > /dev/null
    done
    echo $(($(cat "$work/b$i") + $(now_ns) - t0)) > "$work/b$i"
    i=$((i + 1))
  done
  done_jobs=$((done_jobs + chunk))
done
i=0
for bin in "$@"; do
  printf 'batch    %-50s %8.2f s\n' "$bin" "$(awk '{print $1 / 1e9}' "$work/b$i")"
  i=$((i + 1))
done
echo "(load after: $(cut -d' ' -f1-3 /proc/loadavg))"
