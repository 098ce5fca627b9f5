// Per-texel G-buffer of the lightmap atlas: what the offline stage hands the lighting stage.
#pragma once
#include <cstdint>
#include <vector>

#include "exitance/runtime/lightmap_atlas.h"
#include "exitance/runtime/vec_math.h"

namespace exitance {

struct LiveTexel {
  uint32_t page = 0;
  uint32_t x = 0, y = 0;       // texel column and row (row 0 = top)
  Vec3 position;               // world space, on the surface (after the unocclude push)
  Vec3 geometric_normal;       // unit, front side
  Vec3 shading_normal;         // unit, interpolated vertex normal on the front side
  Vec3 albedo;                 // diffuse albedo at the texel (for bounce passes and debugging)
  uint32_t instance = 0;
  uint32_t triangle = 0;
  float world_texel_size = 0;  // world-space edge length of one texel here
};

struct AtlasPage {
  int width = 0;
  int height = 0;
  std::vector<float> coverage;  // width * height, fraction of each texel covered by charts
};

struct TexelGBuffer {
  std::vector<AtlasPage> pages;
  std::vector<LiveTexel> texels;  // live texels only, page-major, Morton order inside a page
  size_t skipped_texels = 0;      // texels of the pages not covered by any chart
  // Per scene instance, its atlas rectangle (page, scale_offset): how a ray hit finds its texels (the
  // per-bounce gather). Empty for hand-made G-buffers: then no hit has texels.
  std::vector<InstanceRect> instance_rects;
};

}  // namespace exitance
