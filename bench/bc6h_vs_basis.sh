#!/bin/bash
# Issue 19: the BC6H encoder levels side by side with Basis Universal's BC6H (UASTC HDR 4x4
# encoded at LEVEL, then transcoded to BC6H by Basis's transcoder: the one open BC6H encoder
# reachable here; Debian 12 packages none), scored by `vtbake-bench bc6h --reference-blocks` on
# the same pages against the same half floats.
#
#   bench/bc6h_vs_basis.sh [LEVEL] IMAGE.exr...     (env: BUILD, CACHE, HIGH_PAGES, REPEATS)
#
# Basis is a benchmark-only tool: the npm package ktx2-encoder (0.6.0, its basis_encoder.wasm is
# Basis Universal 2.x with UASTC HDR and a BC6H transcoder) is installed into $CACHE by
# `npm install --prefix` and run by node (bench/bc6h_basis.mjs), never linked or shipped. Each
# image is first written as an uncompressed RGBA half EXR (oiiotool; Basis's EXR reader has no
# DWA), and both sides read that file, so they start from the same halves.
set -euo pipefail
LEVEL=${1:-2}
shift || true
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${BUILD:-$ROOT/build/release}
CACHE=${CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/vtbake-bench}
HIGH_PAGES=${HIGH_PAGES:-0}
REPEATS=${REPEATS:-3}
MODULE=$CACHE/ktx2-encoder/node_modules/ktx2-encoder/dist/basis/basis_encoder.js
[ $# -gt 0 ] || { echo "usage: $0 [LEVEL] IMAGE.exr..." >&2; exit 1; }
if [ ! -f "$MODULE" ]; then
  command -v npm >/dev/null || { echo "needs npm to fetch ktx2-encoder into $CACHE" >&2; exit 1; }
  mkdir -p "$CACHE/ktx2-encoder"
  npm install --prefix "$CACHE/ktx2-encoder" --no-audit --no-fund ktx2-encoder@0.6.0 >&2
fi
command -v node >/dev/null || { echo "needs node" >&2; exit 1; }
command -v oiiotool >/dev/null || { echo "needs oiiotool (openimageio-tools)" >&2; exit 1; }
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
mkdir -p "$WORK/in" "$WORK/blocks"
for img in "$@"; do
  oiiotool "$img" --ch R,G,B,A=1.0 -d half --compression none -o "$WORK/in/$(basename "$img")"
done
node "$ROOT/bench/bc6h_basis.mjs" "$MODULE" "$WORK/blocks" "$LEVEL" "$WORK"/in/*.exr | \
  sed 's/^/basis: /'
"$BUILD/bench/vtbake-bench" bc6h --repeats "$REPEATS" --high-pages "$HIGH_PAGES" \
  --reference-blocks "$WORK/blocks" --reference-name "basis-L$LEVEL" "$WORK"/in/*.exr
