#!/bin/bash
# Issue 22: DCT page decode against libjpeg-turbo's, with libjpeg-turbo given its best memory
# layout. Its decode speed in one process depends on where its per-image buffers and the stack
# fall relative to each other (perf puts the slow layouts' extra time on stores and on the
# pushes of its SIMD dispatch: 13-16k or 19-21k Kodak pages/s from the same binary and pages),
# so one process's DCT / JPEG ratio is a draw. This runs `dct_bench --transcode` once per
# layout setting (glibc malloc tunables, address randomisation on and off: 12 processes a
# binary) and reports, per page set, the lowest ratio (JPEG at its luckiest relative to us:
# the conservative figure) and the median. Within a process the two decoders' rounds
# alternate, so a change of machine speed moves both.
#
#   bench/decode_vs_jpeg.sh [ROUNDS] [BINARY...]     (default: build/release/bench/dct_bench)
#
# With DCT_BENCH_GAME_TEXTURES=DIR (e.g. supertuxkart-data unpacked with dpkg -x, its
# share/games/supertuxkart/data/textures), a fourth set: the game data under DIR.
#
# Several binaries (e.g. a copy of an older build's dct_bench first) run side by side, setting
# by setting. Each run is pinned to one core (taskset -c 1); keep the machine otherwise quiet.
set -euo pipefail
ROUNDS=${1:-5}
shift || true
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BINARIES=("$@")
[ ${#BINARIES[@]} -gt 0 ] || BINARIES=("$ROOT/build/release/bench/dct_bench")
SETTINGS=(glibc.malloc.top_pad=0 glibc.malloc.top_pad=4096 glibc.malloc.top_pad=1048576
  glibc.malloc.mmap_threshold=4096 glibc.malloc.mmap_threshold=8192
  glibc.malloc.mmap_threshold=65536)
command -v setarch >/dev/null || { echo "needs setarch (util-linux)" >&2; exit 1; }

OUT=$(mktemp)
trap 'rm -f "$OUT"' EXIT
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
for setting in "${SETTINGS[@]}"; do
  for aslr in on off; do
    for bin in "${BINARIES[@]}"; do
      wrap=(taskset -c 1)
      [ "$aslr" = off ] && wrap=(setarch "$(uname -m)" -R taskset -c 1)
      GLIBC_TUNABLES=$setting "${wrap[@]}" "$bin" --transcode "$ROUNDS" |
        awk -F'|' -v b="$bin" -v s="$setting aslr=$aslr" \
          '/^\| (Kodak fold 0|PBR [^|]*maps|game textures) \|/ { gsub(/^ +| +$/, "", $2);
             printf "%s\t%s\t%s\t%s\t%s\t%s\n", b, s, $2, $8 + 0, $9 + 0, $10 + 0 }' >>"$OUT"
    done
  done
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
python3 - "$OUT" <<'EOF'
import statistics, sys
rows = [l.rstrip("\n").split("\t") for l in open(sys.argv[1]) if l.strip()]
print("\n| binary | pages | DCT / JPEG lowest | median | runs | DCT pages/s median | JPEG pages/s best |")
print("|---|---|---|---|---|---|---|")
keys = []
for r in rows:
    if (r[0], r[2]) not in keys:
        keys.append((r[0], r[2]))
for b, s in keys:
    sel = [r for r in rows if r[0] == b and r[2] == s]
    ratio = [float(r[5]) for r in sel]
    dct = [float(r[3]) for r in sel]
    jpeg = [float(r[4]) for r in sel]
    print("| %s | %s | %.2f | %.2f | %d | %.0f | %.0f |" % (b, s, min(ratio), statistics.median(ratio),
          len(sel), statistics.median(dct), max(jpeg)))
print("\nper run (binary, setting, set, DCT pages/s, JPEG pages/s, ratio):")
for r in rows:
    print("  " + "  ".join(r))
EOF
