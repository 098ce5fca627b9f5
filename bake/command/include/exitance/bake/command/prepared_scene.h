// The offline stage in one call, for benchmarks and tests that need a scene's live texels but
// not a bundle: import -> sky -> atlas layout -> texel raster -> unocclude. (`bake` itself runs
// the same steps in bake_pipeline.cpp, interleaved with its timings, progress and scene checks.)
#pragma once
#include <string>

#include "exitance/bake/layout/atlas_layout.h"
#include "exitance/bake/diagnostics.h"
#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

struct PreparedScene {
  Scene scene;
  TexelGBuffer gbuffer;
};

// `sky` as for --sky ("" = black). Throws InputError for bad input.
PreparedScene prepare_scene_for_lighting(const std::string& path, const std::string& sky, const AtlasSettings& atlas,
                                         Diagnostics& diagnostics);

}  // namespace exitance
