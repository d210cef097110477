#!/usr/bin/env bash
# Sets up a Debian 12 machine, builds vtbake (Release) and runs the main job on the bundled
# sample, writing everything under out/sample/: the procedural sample images (albedo + normal,
# 4096x3072), the page file built from them, and its description.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)"
vtbake=build/release/cli/vtbake
mkdir -p out/sample
"$vtbake" version
"$vtbake" sample -o out/sample
# Progress on the terminal; the JSON summary (pages, bytes, PSNR, stage times) to build.json.
"$vtbake" build --json --layer albedo=out/sample/albedo.png \
  --layer normal=out/sample/normal.png -o out/sample/sample.vtpf >out/sample/build.json
echo "build summary: out/sample/build.json"
if "$vtbake" info --help >/dev/null 2>&1; then
  "$vtbake" info out/sample/sample.vtpf
fi
