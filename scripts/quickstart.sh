#!/usr/bin/env bash
# Installs the Debian packages, builds Exitance (Release) and bakes the Cornell-style sample room.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
./build/bake/bake build/samples/cornell_room.gltf -o build/cornell_room.bake --texel-density 16 --spp 128
echo "Lightmap bundle: build/cornell_room.bake (manifest.json + lightmap-0.exr)"
