#!/bin/sh
# Builds bench_vulkan_replay: the Vulkan backend's sources plus bench/vulkan/replay_*.cpp, linked
# against nothing but the Vulkan loader (libstdc++ and libgcc static), so the binary runs on a
# machine that has only a Vulkan driver (the GPU machine; see bench/results/vulkan-gpu.md).
#   bench/vulkan/build_replay.sh BUILD_DIR OUTPUT   (BUILD_DIR: a configured build whose
#   runtime/generated/exitance_spirv holds the SPIR-V headers, e.g. after `ninja exitance_vulkan`)
set -eu
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$1
out=$2
ninja -C "$build" exitance_vulkan >/dev/null
${CXX:-g++} -std=c++20 -O2 -DNDEBUG -Wno-missing-field-initializers \
  -I"$root/runtime/include" -I"$root/runtime/common/include" -I"$root/runtime/src/vulkan" -I"$build/runtime/generated" \
  "$root/runtime/src/vulkan/vulkan_context.cpp" "$root/runtime/src/vulkan/vulkan_integrator.cpp" \
  "$root/runtime/src/core/lighting_scene.cpp" "$root/runtime/src/core/pass_scheduler.cpp" \
  "$root/runtime/src/material_eval.cpp" \
  "$root/runtime/src/environment_sampler.cpp" "$root/runtime/src/lightmap_estimate.cpp" \
  "$root/bench/vulkan/replay_main.cpp" \
  -static-libstdc++ -static-libgcc -lvulkan -o "$out"
