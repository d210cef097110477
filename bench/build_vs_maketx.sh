#!/usr/bin/env bash
# `vtbake build` against OpenImageIO's `maketx` on the same generated SIZE x SIZE image (default
# 16384), in one run: wall time, CPU time and peak memory from /usr/bin/time -v. Then the peak
# memory of building a BIG x BIG virtual texture (default 65536, generated procedurally, no
# input file) under --memory-limit LIMIT (default 1G). Prints a Markdown table.
#   VTBAKE=build/release/cli/vtbake SIZE=16384 BIG=65536 LIMIT=1G bash bench/build_vs_maketx.sh
set -euo pipefail
cd "$(dirname "$0")/.."
vtbake=${VTBAKE:-build/release/cli/vtbake}
size=${SIZE:-16384}
big=${BIG:-65536}
limit=${LIMIT:-1G}
dir=${DIR:-out/bench-build}
mkdir -p "$dir"
input="$dir/albedo_${size}.tif"
if [ ! -f "$input" ]; then
  "$vtbake" sample -o "$dir/gen" --width "$size" --height "$size" --ext tif --albedo-only --quiet
  mv "$dir/gen/albedo.tif" "$input"
fi

echo "| run | wall s | user+sys s | peak RSS MiB | output MiB |"
echo "| --- | ---: | ---: | ---: | ---: |"
run() {
  local name=$1 out=$2
  shift 2
  rm -f "$out"
  /usr/bin/time -v "$@" >/dev/null 2>"$dir/$name.time"
  awk -v name="$name" -v out_bytes="$(stat -c %s "$out")" '
    /Elapsed \(wall clock\)/ { n = split($NF, t, ":"); wall = 0; for (i = 1; i <= n; ++i) wall = wall * 60 + t[i] }
    /User time/ { cpu += $NF } /System time/ { cpu += $NF }
    /Maximum resident set size/ { rss = $NF / 1024 }
    END { printf "| %s | %.1f | %.1f | %.0f | %.1f |\n", name, wall, cpu, rss, out_bytes / 1048576 }' \
    "$dir/$name.time"
}
run "vtbake build (kaiser, dct q75)" "$dir/k.vtpf" "$vtbake" build --quiet "$input" -o "$dir/k.vtpf"
run "vtbake build (box, dct q75)" "$dir/b.vtpf" "$vtbake" build --quiet --filter box "$input" -o "$dir/b.vtpf"
run "vtbake build (kaiser, raw+zstd)" "$dir/r.vtpf" "$vtbake" build --quiet --codec raw "$input" -o "$dir/r.vtpf"
run "maketx (defaults: box)" "$dir/m.tx" maketx "$input" -o "$dir/m.tx"
run "maketx --filter lanczos3" "$dir/l.tx" maketx --filter lanczos3 "$input" -o "$dir/l.tx"
if [ "$big" != 0 ]; then
  run "vtbake build procedural:${big}x${big} --memory-limit $limit" "$dir/big.vtpf" \
    "$vtbake" build --quiet --memory-limit "$limit" "procedural:${big}x${big}" -o "$dir/big.vtpf"
  rm -f "$dir/big.vtpf"
fi
