// The cache key of a bake: one SHA-256 over everything its bundle depends on - the program that
// bakes (its executable's bytes), the Vulkan devices `--backend auto` chooses among, the input
// file's name and bytes (the manifest records both), the imported scene's content (geometry,
// materials, texture pixels, lights, sky, nodes: what external buffers and images contributed),
// and every option. Two runs with the same key write the same bundle (results are deterministic per
// seed and backend; a --time run is as good as any other run of that budget).
#pragma once
#include <string>

#include "exitance/bake/bake_options.h"
#include "exitance/runtime/scene.h"

namespace exitance {

// SHA-256 of this process's executable (/proc/self/exe), computed once; "" when unreadable.
const std::string& program_identity();

// `devices`: a description of the Vulkan devices present (empty when --backend cpu).
std::string bake_cache_key(const Scene& scene, const BakeOptions& options, const std::string& input_sha256,
                           const std::string& devices);

}  // namespace exitance
