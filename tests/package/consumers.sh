#!/usr/bin/env bash
# The consumer test: installs the runtime component of a built tree into a fresh prefix, then
# builds and runs tests/package/consumer against it twice: with find_package(vtbake) (a C99, a
# C++17 and a C++20 program) and with pkg-config (the C99 and C++17 programs, by hand).
# usage: consumers.sh BUILD_DIR WORK_DIR CC CXX
set -euo pipefail
build=$1 work=$2 cc=$3 cxx=$4
here=$(cd "$(dirname "$0")" && pwd)
src=$here/consumer

rm -rf "$work"
mkdir -p "$work"
prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" --component runtime >"$work/install.log"

# Nothing internal may be installed: only the headers marked public, under vtbake/.
if find "$prefix/include" -name '*.h' | grep -v "^$prefix/include/vtbake/" ; then
  echo "headers installed outside include/vtbake/" >&2
  exit 1
fi
for internal in format/page_file_layout.h format/c_api_internal.h format/layer_codec.h; do
  if [[ -e $prefix/include/vtbake/$internal ]]; then
    echo "internal header installed: $internal" >&2
    exit 1
  fi
done

echo "== find_package"
cmake -S "$src" -B "$work/cmake" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" \
  >"$work/configure.log"
cmake --build "$work/cmake" >"$work/build.log" || { cat "$work/build.log"; exit 1; }
"$work/cmake/write_page_file" "$work/pages.vtpf"
"$work/cmake/stream_c" "$work/pages.vtpf"
"$work/cmake/stream_cxx17" "$work/pages.vtpf"

echo "== pkg-config"
pc_dir=$(dirname "$(find "$prefix" -name vtbake-runtime.pc)")
export PKG_CONFIG_PATH=$pc_dir
cflags=$(pkg-config --cflags vtbake-runtime)
libs=$(pkg-config --libs vtbake-runtime)
# A shared build's libraries live in a private prefix: the programs find them by rpath.
libs+=" -Wl,-rpath,$(pkg-config --variable=libdir vtbake-runtime)"
echo "pkg-config --libs vtbake-runtime: $libs"
# shellcheck disable=SC2086
"$cc" -std=c99 -pedantic-errors -Wall -Wextra $cflags "$src/stream_frames.c" -o "$work/pc_c" $libs
# shellcheck disable=SC2086
"$cxx" -std=c++17 -pedantic-errors -Wall -Wextra -I"$src" $cflags "$src/stream_frames_cxx17.cpp" \
  -o "$work/pc_cxx17" $libs
"$work/pc_c" "$work/pages.vtpf"
"$work/pc_cxx17" "$work/pages.vtpf"
echo "consumer test: 5 programs built against $prefix and run"
