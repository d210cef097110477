#!/usr/bin/env bash
# Unwrap benchmark: vtbake unwrap on the meshes of ../shared/testdata/meshes that ANCHORS.md
# measured xatlas on; charts, coverage with 0 and 4 texels of padding, L2 stretch and time;
# then LSCM vs ARAP vs split-and-redo rounds on a few meshes. Prints Markdown tables.
#   bash bench/unwrap_bench.sh [BUILD_DIR] [TESTDATA_DIR]
set -euo pipefail
BUILD=${1:-build/release}
DATA=${2:-$(cd "$(dirname "$0")/../.." && pwd)/shared/testdata/meshes}
VTBAKE=$BUILD/cli/vtbake
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT

MESHES=(
  textured/Duck/Duck.gltf
  textured/DamagedHelmet/DamagedHelmet.gltf
  textured/CesiumMilkTruck/CesiumMilkTruck.gltf
  scene/VirtualCity/VC.gltf
  hard/many_components/ReciprocatingSaw/ReciprocatingSaw.gltf
  hard/many_components/BrainStem/BrainStem.gltf
  hard/genus/cheese_genus133.ply
  hard/open_boundaries/bun_zipper.ply
  large/nefertiti.obj
  large/ogre.obj
  large/igea_268k.ply
  large/igea_1M_loop1.drc
)
SIZE=${UNWRAP_BENCH_SIZE:-16}

run() {  # run NAME MESH ARGS... -> writes $OUT/NAME.json, prints wall seconds
  local name=$1 mesh=$2
  shift 2
  # Wall and CPU (user + sys) seconds of the whole command, load included: on a shared
  # machine CPU seconds are the figure that compares.
  if ! /usr/bin/time -f "%e %U %S" -o "$OUT/$name.time" "$VTBAKE" --json -q unwrap "$DATA/$mesh" \
      -o "$OUT/$name.glb" --size "$SIZE" "$@" >"$OUT/$name.json" 2>"$OUT/$name.err"; then
    echo "FAILED $mesh $*: $(tail -1 "$OUT/$name.err")" >&2
  fi
  tail -1 "$OUT/$name.time" | awk '{printf "%.2f / %.2f", $1, $2 + $3}' >"$OUT/$name.wall"
}

echo "| mesh | triangles | charts | coverage (pad 0) | coverage (pad 4) | L2 | Linf | flipped | overlapping texels | time s (pad 4): wall / CPU |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for mesh in "${MESHES[@]}"; do
  [ -n "${SKIP_MAIN:-}" ] && break
  [ -f "$DATA/$mesh" ] || { echo "| $mesh | missing | | | | | | | | |"; continue; }
  key=$(echo "$mesh" | tr '/.' '__')
  run "${key}_p0" "$mesh" --padding 0
  run "${key}_p4" "$mesh" --padding 4
  python3 - "$OUT/${key}_p0.json" "$OUT/${key}_p4.json" "$(cat "$OUT/${key}_p4.wall")" "$mesh" <<'PY'
import json, sys
def load(p):
    try: return json.load(open(p))
    except Exception: return None
a, b, wall, mesh = load(sys.argv[1]), load(sys.argv[2]), sys.argv[3], sys.argv[4]
if not a or not b:
    print(f"| {mesh} | failed | | | | | | | | |"); sys.exit()
print(f"| {mesh} | {b['faces']:,} | {b['charts']:,} | {a['utilisation']:.3f} | {b['utilisation']:.3f} | "
      f"{b['stretch']['l2']:.4f} | {b['stretch']['linf']:.2f} | {b['flipped_triangles']} | {b['overlapping_texels']} | {wall} |")
PY
done

echo
echo "Load average at start: $(cut -d' ' -f1-3 /proc/loadavg), $(nproc) cores"
echo
echo "What accuracy costs (padding 4, --chart-angle 90 --max-stretch 1.02 so that charts are curved"
echo "enough for the split-and-redo rounds to matter): method and rounds against time"
echo
echo "| mesh | method | stretch split rounds | charts | coverage | L2 | time s: wall / CPU |"
echo "|---|---|---|---|---|---|---|"
for mesh in ${METHOD_MESHES:-textured/Duck/Duck.gltf hard/open_boundaries/bun_zipper.ply}; do
  [ -f "$DATA/$mesh" ] || continue
  key=$(echo "$mesh" | tr '/.' '__')
  for cfg in "lscm 0" "lscm 1" "lscm 2" "lscm 4" "arap 0" "arap 4"; do
    set -- $cfg
    run "${key}_$1_$2" "$mesh" --padding 4 --method "$1" --split-rounds "$2" --chart-angle 90 --max-stretch 1.02
    python3 - "$OUT/${key}_$1_$2.json" "$(cat "$OUT/${key}_$1_$2.wall")" "$mesh" "$1" "$2" <<'PY'
import json, sys
try: r = json.load(open(sys.argv[1]))
except Exception: r = None
mesh, method, rounds = sys.argv[3], sys.argv[4], sys.argv[5]
if not r: print(f"| {mesh} | {method} | {rounds} | failed | | | |"); sys.exit()
print(f"| {mesh} | {method} | {rounds} | {r['charts']:,} | {r['utilisation']:.3f} | {r['stretch']['l2']:.4f} | {sys.argv[2]} |")
PY
  done
done
