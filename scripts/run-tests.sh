#!/usr/bin/env bash
# Sets up a Debian 12 machine, builds vtbake and runs the whole test suite: the runtime side
# (codec, format, runtime) under ASan/UBSan, then every fuzz target for a bounded time (clang,
# libFuzzer, ASan/UBSan; any finding fails), the runtime side cross-compiled for Windows
# (mingw-w64), then everything in Release. Ends with ctest's summary.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
jobs=$(nproc)

cmake --preset asan-runtime >/dev/null
cmake --build --preset asan-runtime -j "$jobs"
ctest --preset asan-runtime -j "$jobs"

cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j "$jobs"
fuzz/run.sh --build build/fuzz --seconds "${VTBAKE_FUZZ_SECONDS:-20}" --jobs "$jobs"

bash tests/package/cross_windows.sh build/mingw "$jobs"  # the runtime side for Windows (mingw-w64)

cmake --preset release >/dev/null
cmake --build --preset release -j "$jobs"
ctest --preset release -j "$jobs"
