#!/usr/bin/env bash
# The conformance run (issue 14): bakes and validates every model of Debian's assimp-testmodels
# package that has a material (glTF 2.0) or carries textures (OBJ, FBX, COLLADA, PLY, 3DS,
# AC3D), and writes the table to docs/CONFORMANCE.md (or --out FILE). The corpus is fetched
# with apt-get download and unpacked with dpkg -x into a cache folder outside the repository;
# nothing of it is ever committed. Not part of the CI suite: `ctest -L conformance` runs it.
#
#   scripts/conformance.sh [--vtbake PATH] [--corpus DIR] [--work DIR] [--out FILE]
#                          [--only REGEX] [--timeout SECONDS]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
vtbake="$root/build/release/cli/vtbake"
cache="${XDG_CACHE_HOME:-$HOME/.cache}/vtbake-conformance"
corpus=""
work=""
out="$root/docs/CONFORMANCE.md"
only=""
timeout_s=600
while [[ $# -gt 0 ]]; do
  case "$1" in
    --vtbake) vtbake="$2"; shift 2 ;;
    --corpus) corpus="$2"; shift 2 ;;
    --work) work="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --only) only="$2"; shift 2 ;;
    --timeout) timeout_s="$2"; shift 2 ;;
    *) echo "conformance: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
command -v python3 >/dev/null || { echo "conformance: needs python3 (apt-get install python3)" >&2; exit 2; }
[[ -x "$vtbake" ]] || { echo "conformance: no vtbake at $vtbake (build first)" >&2; exit 2; }

if [[ -z "$corpus" ]]; then
  corpus="$cache/assimp-testmodels/usr/share/assimp/models"
  if [[ ! -d "$corpus" ]]; then
    mkdir -p "$cache"
    (cd "$cache" && rm -f assimp-testmodels_*.deb && apt-get download assimp-testmodels >/dev/null &&
      dpkg -x assimp-testmodels_*.deb "$cache/assimp-testmodels")
  fi
fi
[[ -d "$corpus" ]] || { echo "conformance: corpus folder $corpus does not exist" >&2; exit 2; }
# One work folder per checkout, so that worktrees running at once never share files.
work="${work:-$cache/work-$(basename "$root")}"
mkdir -p "$work"
exec python3 "$root/scripts/conformance.py" --vtbake "$vtbake" --corpus "$corpus" --work "$work" \
  --out "$out" --only "$only" --timeout "$timeout_s"
