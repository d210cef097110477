#!/usr/bin/env bash
# Sets up a Debian 12 machine, builds vtbake (Release) and runs the main job on the bundled
# sample scene, writing everything under out/sample/: the procedural scene (meshes, materials,
# textures in sRGB PNG and linear EXR), the baked page file and unwrapped scene, the page file's
# description, and the validation renders and report (lavapipe, no GPU needed).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)"
vtbake=build/release/cli/vtbake
out=out/sample
mkdir -p "$out"
"$vtbake" sample-scene "$out/scene"
# Progress on the terminal, then the summary (layers, pages, bytes, time per stage).
"$vtbake" bake "$out/scene/scene.gltf" -o "$out/scene.vtpf"
"$vtbake" info "$out/scene.vtpf"
"$vtbake" verify "$out/scene.vtpf"
# Renders the baked scene through the virtual-texture path and the original materials, compares.
"$vtbake" validate "$out/scene/scene.gltf" "$out/scene.vtpf" --out "$out/validate"
echo "outputs: $out/scene.vtpf, $out/scene.glb, $out/validate/ (renders, difference maps, report.json)"
