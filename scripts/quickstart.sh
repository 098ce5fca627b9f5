#!/usr/bin/env bash
# Installs the Debian packages, builds Exitance (Release), bakes the Cornell-style sample room,
# reads the bundle back with the loader sample (the program an engine would write) and re-lights it
# with the runtime's exitance-relight.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
# Only what this script runs (the tests and benches build in scripts/run-tests.sh).
cmake --build build -j"$(nproc)" --target bake exitance_loader_sample exitance-relight sample_scenes
./build/bake/bake build/samples/cornell_room.gltf -o build/cornell_room.bake --texel-density 16 --spp 128
./build/samples/loader_sample/exitance_loader_sample build/cornell_room.bake
# The runtime re-lights the bundle from its scene.bin on Vulkan (lavapipe here; a GPU elsewhere). The first
# run on a machine compiles the kernels (lavapipe: 20-60 s with LLVM; Mesa caches them for later runs).
./build/runtime/exitance-relight build/cornell_room.bake -o build/cornell_room.relit.bake --spp 8
echo "Bundle: build/cornell_room.bake (manifest.json, lightmap-0.exr, probes.bin, svo.bin, scene.bin, radiance.vdb);"
echo "re-lit by the runtime at 8 spp: build/cornell_room.relit.bake"
