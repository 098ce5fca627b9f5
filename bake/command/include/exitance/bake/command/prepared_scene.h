// The offline stage up to the lighting, for benchmarks and tests that need a scene's live texels but
// not a bundle: the import, layout, raster and unocclude stages of bake_stages.h, as `bake` runs
// them (without its timings, scene checks, voxelization and probes).
#pragma once
#include <string>

#include "exitance/bake/diagnostics.h"
#include "exitance/bake/layout/atlas_layout.h"
#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

struct PreparedScene {
  Scene scene;
  TexelGBuffer gbuffer;
  AtlasLayout layout;
};

// `sky` as for --sky ("" = black). Throws InputError for bad input.
PreparedScene prepare_scene_for_lighting(const std::string& path, const std::string& sky, const AtlasSettings& atlas,
                                         Diagnostics& diagnostics);

}  // namespace exitance
