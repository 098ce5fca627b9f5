// Conservative rasterization of every triangle in lightmap UV space: each texel touched by a
// chart becomes live and takes the triangle that covers most of it.
#pragma once
#include "exitance/bake/layout/atlas_layout.h"
#include "exitance/bake/diagnostics.h"
#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

TexelGBuffer rasterize_texel_gbuffer(const Scene& scene, const AtlasLayout& layout, const std::string& file,
                                     Diagnostics& diagnostics);

// Area of the part of the unit texel square [x,x+1]x[y,y+1] inside the triangle (any winding),
// and the centroid of that part. Exposed for unit tests.
float clipped_texel_coverage(const Vec2 triangle[3], int x, int y, Vec2& centroid);

}  // namespace exitance
