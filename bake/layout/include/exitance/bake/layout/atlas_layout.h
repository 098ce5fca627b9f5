// One rectangle per mesh instance, packed into atlas pages (shelf packing, tallest first).
#pragma once
#include <vector>

#include "exitance/bake/diagnostics.h"
#include "exitance/runtime/scene.h"

namespace exitance {

struct AtlasSettings {
  float texel_density = 0;  // texels per scene unit; <= 0 = automatic
  int max_page = 2048;      // page size limit in texels
  int padding = 2;          // texels of gutter around every rectangle
  size_t max_total_texels = size_t(16) << 20;  // automatic density never exceeds this many texels
};

struct InstanceRect {
  int page = 0;
  int x = 0, y = 0;           // top-left texel of the chart area (inside the padding)
  int width = 0, height = 0;  // texels
  float scale_offset[4] = {1, 1, 0, 0};  // page_uv = lightmap_uv * s + o (manifest convention)
};

struct AtlasLayout {
  float texel_density = 0;  // the density actually used
  std::vector<std::pair<int, int>> page_sizes;  // width, height
  std::vector<InstanceRect> rects;              // one per scene instance
  size_t capped_instances = 0;                  // rectangles shrunk to fit --max-page
};

AtlasLayout layout_lightmap_atlas(const Scene& scene, const AtlasSettings& settings, const std::string& file,
                                  Diagnostics& diagnostics);

// The density bake uses when the user gives none: 64 texels per unit for a room-sized scene,
// lowered for large scenes so the atlas stays under `max_total_texels`.
float automatic_texel_density(const Scene& scene, size_t max_total_texels);

}  // namespace exitance
