#!/usr/bin/env bash
# Transfer throughput of two vtbake builds on one scene, side by side (issue 16): ROUNDS rounds,
# each running A then B (interleaved, so load drifts hit both), one thread, supersample 1.
# Prints each run's transfer seconds and covered texels, then the medians of covered texels per
# second per core and their ratio B / A.
#   bench/transfer_side_by_side.sh VTBAKE_A VTBAKE_B SCENE OUTDIR [PAGES] [ROUNDS] [EXTRA FLAGS]
# e.g. bench/transfer_side_by_side.sh /work/wt/base/build/release/cli/vtbake \
#        build/release/cli/vtbake /work/shared/testdata/meshes/scene/VirtualCity/VC.gltf \
#        /tmp/xfer 35 5
set -euo pipefail
a=$1 b=$2 scene=$3 out=$4 pages=${5:-35} rounds=${6:-5}
shift $(($# < 6 ? $# : 6))
mkdir -p "$out"
uptime
for r in $(seq 1 "$rounds"); do
  for which in A B; do
    exe=$a
    [ "$which" = B ] && exe=$b
    json=$out/$which-$r.json
    "$exe" --json --threads 1 bake "$scene" --size "$pages" --supersample 1 --unwrapped - \
      -o "$out/$which.vtpf" "$@" > "$json"
    python3 - "$json" "$which" "$r" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
t = j["seconds"]["transfer"]; c = j["transfer"]["covered_texels"]
print("%s round %s: transfer %.2f s, %d covered texels, %.0f texels/s/core" % (
    sys.argv[2], sys.argv[3], t, c, c / t))
PY
  done
done
uptime
python3 - "$out" "$rounds" <<'PY'
import json, statistics, sys
out, rounds = sys.argv[1], int(sys.argv[2])
rate = {}
for w in "AB":
    v = []
    for r in range(1, rounds + 1):
        j = json.load(open("%s/%s-%d.json" % (out, w, r)))
        v.append(j["transfer"]["covered_texels"] / j["seconds"]["transfer"])
    rate[w] = statistics.median(v)
    print("%s median %.0f covered texels/s/core (min %.0f, max %.0f)" % (w, rate[w], min(v), max(v)))
print("B / A = %.2f" % (rate["B"] / rate["A"]))
PY
