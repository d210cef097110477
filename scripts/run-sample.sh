#!/usr/bin/env bash
# Sets up a Debian 12 machine, builds vtbake (Release) and runs the main job on the bundled
# sample, writing everything under out/sample/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)"
vtbake=build/release/cli/vtbake
mkdir -p out/sample
"$vtbake" version
