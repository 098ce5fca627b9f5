// Conservative rasterization of every triangle in lightmap UV space: each texel touched by a
// chart becomes live and takes the triangle that covers most of it. The per-texel geometry
// (clipped_texel_coverage, chart_barycentrics, texel_surface) is in exitance/runtime/texel_surface.h.
#pragma once

#include "exitance/bake/raster/parallel_progress.h"
#include "exitance/bake/layout/atlas_layout.h"
#include "exitance/bake/diagnostics.h"
#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"
#include "exitance/runtime/texel_surface.h"

namespace exitance {

// `progress` (optional) hears the share done (instances rasterized, then texels filled in).
TexelGBuffer rasterize_texel_gbuffer(const Scene& scene, const AtlasLayout& layout, const std::string& file,
                                     Diagnostics& diagnostics, const FractionDone& progress = {});

}  // namespace exitance
