#!/usr/bin/env bash
# Installs the Debian packages, builds Exitance (Release), bakes the Cornell-style sample room and
# reads the bundle back with the loader sample (the program an engine would write).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
./build/bake/bake build/samples/cornell_room.gltf -o build/cornell_room.bake --texel-density 16 --spp 128
./build/samples/loader_sample/exitance_loader_sample build/cornell_room.bake
echo "Bundle: build/cornell_room.bake (manifest.json, lightmap-0.exr, probes.bin, svo.bin, radiance.vdb)"
