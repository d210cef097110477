#!/usr/bin/env bash
# Installs what vtbake needs on Debian 12, with apt-get, only if something is missing.
# Idempotent and quiet when everything is already there.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config clang-format
  libopenimageio-dev openimageio-tools libopenexr-dev libopencolorio-dev
  libcgal-dev libeigen3-dev libtbb-dev libdraco-dev libmeshoptimizer-dev libassimp-dev
  libzstd-dev libxxhash-dev zlib1g-dev libembree-dev
  libcli11-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libvulkan-dev glslc mesa-vulkan-drivers
  libjpeg62-turbo-dev libstb-dev
  clang libclang-rt-14-dev
  help2man g++-mingw-w64-x86-64-posix
  slurm-wlm munge
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done
[[ ${#missing[@]} -eq 0 ]] && exit 0

echo "setup: installing ${missing[*]}"
sudo_cmd=()
[[ $(id -u) -eq 0 ]] || sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
