// Reads a .gltf/.glb file into a tinygltf::Model after checking the container itself
// (GLB header and chunk sizes, glTF version, required extensions). Images are kept as raw
// bytes (decoded later by OpenImageIO, only when a material uses them).
#pragma once
#include <string>

#include <tiny_gltf.h>

#include "exitance/bake/diagnostics.h"

namespace exitance {

tinygltf::Model load_gltf_model(const std::string& path, Diagnostics& diagnostics);

// Extensions the importer understands; a file that *requires* any other one is refused.
bool is_supported_gltf_extension(const std::string& name);

}  // namespace exitance
