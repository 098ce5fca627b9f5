// glTF 2.0 → Scene: the default scene's node hierarchy flattened to world space.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "exitance/bake/diagnostics.h"
#include "exitance/runtime/scene.h"

namespace exitance {

struct ImportOptions {
  int lightmap_uv_set = 1;             // TEXCOORD_1 by default; --uv 0 selects TEXCOORD_0
  bool generate_lightmap_uvs = false;  // --uv generate: every mesh's lightmap UVs are generated
};

// A glTF mesh whose lightmap UVs are to be generated (it lacks the chosen set on some triangle
// primitive, or --uv generate): its triangles in mesh-local space, all triangle primitives together
// in glTF order, and where each instance's scene triangles came from. Its instances' lightmap_uv
// entries are zeros until bake/uvgen fills them.
struct MeshWithoutLightmapUvs {
  int mesh = -1;
  std::string name;
  std::string missing_set;          // "TEXCOORD_1" when absent from the file; "" with --uv generate
  std::vector<Vec3> positions;      // mesh-local, every triangle primitive's vertices
  std::vector<uint32_t> indices;    // 3 per mesh triangle, into `positions`
  struct InstanceCorners {
    uint32_t instance = 0;          // index into Scene::instances
    std::vector<uint32_t> corners;  // per scene corner of the instance, its mesh corner (3 triangle + k)
  };
  std::vector<InstanceCorners> instances;
};

// Throws InputError for bad input; repairs (degenerate triangles, bad normals) become warnings.
// A mesh without the chosen lightmap UV set is an InputError when `without_lightmap_uvs` is null;
// otherwise it is listed there for bake/uvgen (generate_missing_lightmap_uvs).
Scene import_gltf(const std::string& path, const ImportOptions& options, Diagnostics& diagnostics,
                  std::vector<MeshWithoutLightmapUvs>* without_lightmap_uvs = nullptr);

}  // namespace exitance
