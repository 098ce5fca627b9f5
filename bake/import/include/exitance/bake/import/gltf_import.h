// glTF 2.0 → Scene: the default scene's node hierarchy flattened to world space.
#pragma once
#include <string>

#include "exitance/bake/diagnostics.h"
#include "exitance/runtime/scene.h"

namespace exitance {

struct ImportOptions {
  int lightmap_uv_set = 1;  // TEXCOORD_1 by default; --uv 0 selects TEXCOORD_0
};

// Throws InputError for bad input; repairs (degenerate triangles, bad normals) become warnings.
Scene import_gltf(const std::string& path, const ImportOptions& options, Diagnostics& diagnostics);

}  // namespace exitance
