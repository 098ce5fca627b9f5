// The "unocclude" step: texel centres that fall inside or behind nearby geometry (a floor
// texel under a wall) are pushed out to the visible side, so corners do not go black.
#pragma once

#include "exitance/bake/raster/parallel_progress.h"
#include "exitance/runtime/embree_scene.h"
#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

struct UnoccludeReport {
  size_t moved = 0;
};

// `progress` (optional) hears the share of texels done.
UnoccludeReport unocclude_texels(const EmbreeScene& embree, TexelGBuffer& gbuffer, const FractionDone& progress = {});

}  // namespace exitance
