#!/usr/bin/env bash
# Cross-compiles the runtime side (codec/, format/ reader, runtime/) for Windows with Debian's
# mingw-w64 and archives it, proving no POSIX-only call is left outside format/platform_file.cpp.
# Debian ships no Windows zstd or xxhash libraries, so this compiles and archives objects (their
# headers come from the host) but links no program; the unit tests do not run under wine.
# The writer side of format/ (page_file_writer.cpp, atomic_output.cpp: temp files, fsync,
# renames) is the baker's and stays POSIX.
# usage: cross_windows.sh OUT_DIR [JOBS]
set -euo pipefail
out=$1 jobs=${2:-2}
root=$(cd "$(dirname "$0")/../.." && pwd)
cxx=x86_64-w64-mingw32-g++-posix
cc=x86_64-w64-mingw32-gcc-posix
ar=x86_64-w64-mingw32-ar
command -v "$cxx" >/dev/null || { echo "cross_windows: $cxx missing (scripts/setup.sh installs it)" >&2; exit 1; }

rm -rf "$out"
mkdir -p "$out/shim" "$out/obj"
# Only the two headers the sources need, not the host's whole /usr/include.
for h in zstd.h zstd_errors.h xxhash.h; do ln -s "/usr/include/$h" "$out/shim/$h"; done

cd "$root"
# format/version.cpp gets the project version from CMake; here it is read from project().
version=$(sed -n 's/^project(vtbake VERSION \([0-9]*\)\.\([0-9]*\)\.\([0-9]*\).*/\1 \2 \3/p' CMakeLists.txt)
read -r major minor patch <<<"$version"
version_flags="-DVT_LIBRARY_VERSION_MAJOR=$major -DVT_LIBRARY_VERSION_MINOR=$minor -DVT_LIBRARY_VERSION_PATCH=$patch"
posix_only=(format/page_file_writer.cpp format/atomic_output.cpp)
sources=()
for f in codec/*.cpp codec/*.c format/*.cpp format/*.c runtime/*.cpp runtime/*.c; do
  [[ -e $f ]] || continue
  [[ " ${posix_only[*]} " == *" $f "* ]] && continue
  sources+=("$f")
done

compile() {
  local f=$1 obj=$out/obj/${1//\//_}.o
  case $f in
    *.c) "$cc" -std=c99 -Wall -Wextra -pedantic-errors -I"$root" -c "$f" -o "$obj" ;;
    *) "$cxx" -std=c++20 -O1 -Wall -Wextra -I"$root" -I"$out/shim" -ffp-contract=off $version_flags -c "$f" -o "$obj" ;;
  esac
}
export -f compile
export out root cc cxx version_flags
printf '%s\n' "${sources[@]}" | xargs -P "$jobs" -I{} bash -c 'compile {} || { echo "cross_windows: {} failed" >&2; exit 255; }'
"$ar" rcs "$out/libvtbake_runtime_win64.a" "$out"/obj/*.o
echo "cross_windows: ${#sources[@]} runtime-side sources compiled for x86_64-w64-mingw32 into $out/libvtbake_runtime_win64.a ($(stat -c %s "$out/libvtbake_runtime_win64.a") bytes)"
