#!/usr/bin/env bash
# Installs every Debian 12 package Exitance needs to build, test and benchmark (DESIGN §8).
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
packages=(
  build-essential cmake ninja-build pkg-config git python3 ccache
  clang libclang-rt-14-dev
  libembree-dev libtbb-dev
  libopenvdb-dev libopenvdb-tools
  libopenexr-dev libdeflate-dev libopenimageio-dev openimageio-tools
  libtinygltf-dev libstb-dev nlohmann-json3-dev libcli11-dev
  libcgal-dev libeigen3-dev
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers vulkan-tools glslang-tools
  libgtest-dev libgmock-dev libbenchmark-dev
  libssl-dev
  libopenmpi-dev openmpi-bin
  assimp-testmodels
  python3-matplotlib gnuplot-nox
)
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${packages[@]}"
