#!/usr/bin/env bash
# Scene bake throughput (covered texels per second of the transfer, whole-bake time) and peak
# memory (/usr/bin/time -v) of `vtbake bake` on the procedural sample scene, at supersampling
# 1, 4 and 16, and on a version of it with more than 1M triangles. Prints a Markdown table.
#   bash bench/scene_bake_bench.sh [BUILD_DIR] [WORK_DIR]
# Supersampling accuracy versus time is measured by bench/gbench/transfer_bench.cpp.
set -euo pipefail
BUILD=${1:-build/release}
WORK=${2:-$(mktemp -d /tmp/vtbake-scene-bench.XXXXXX)}
VTBAKE=$BUILD/cli/vtbake
THREADS=${THREADS:-0}
[ -x "$VTBAKE" ] || { echo "no $VTBAKE: build the release preset first" >&2; exit 2; }
[ -x /usr/bin/time ] || { echo "needs /usr/bin/time (apt-get install time)" >&2; exit 2; }

"$VTBAKE" --quiet sample-scene "$WORK/sample"
"$VTBAKE" --quiet sample-scene "$WORK/large" --sphere-segments 1000 --ground-cells 64

run() {  # name scene supersample extra-flags...
  local name=$1 scene=$2 ss=$3
  shift 3
  /usr/bin/time -v "$VTBAKE" --quiet --json --threads "$THREADS" bake "$scene" \
    -o "$WORK/$name.vtpf" --supersample "$ss" "$@" >"$WORK/$name.json" 2>"$WORK/$name.time"
  python3 - "$WORK/$name.json" "$WORK/$name.time" "$name" "$ss" <<'EOF'
import json, re, sys
j = json.load(open(sys.argv[1]))
t = open(sys.argv[2]).read()
rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", t).group(1))
s = j["seconds"]
tr = j["transfer"]
print(f"| {sys.argv[3]} | {j['triangles']:,} | {j['atlas']['width']}x{j['atlas']['height']} | {sys.argv[4]} "
      f"| {tr['covered_texels']:,} | {s['transfer']:.2f} | {tr['texels_per_second']/1e6:.2f} "
      f"| {s['unwrap']:.2f} | {s['build']:.2f} | {j['seconds']['total']:.2f} | {j['build']['bytes']['file']:,} "
      f"| {j['build']['bytes']['ratio']:.1f} | {rss/1024:.0f} |")
EOF
}

echo "| scene | triangles | atlas | ss | covered texels | transfer s | Mtexels/s | unwrap s | build s | total s | file bytes | ratio | peak RSS MiB |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for ss in 1 4 16; do run "sample_ss$ss" "$WORK/sample/scene.gltf" "$ss"; done
run "large_ss1" "$WORK/large/scene.gltf" 1 --size 32
