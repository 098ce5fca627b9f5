// The lightmap atlas layout: one rectangle per mesh instance on an atlas page. Made by the offline
// stage (bake/atlas_layout.h, layout_lightmap_atlas) and restored from scene.bin by the runtime, so
// the types live here where both can use them.
#pragma once
#include <cstddef>
#include <utility>
#include <vector>

namespace exitance {

struct InstanceRect {
  int page = 0;
  int x = 0, y = 0;                      // top-left texel of the chart area (inside the padding)
  int width = 0, height = 0;             // texels
  float scale_offset[4] = {1, 1, 0, 0};  // page_uv = lightmap_uv * s + o (manifest convention)
};

struct AtlasLayout {
  float texel_density = 0;                      // the density actually used
  std::vector<std::pair<int, int>> page_sizes;  // width, height
  std::vector<InstanceRect> rects;              // one per scene instance
  size_t capped_instances = 0;                  // rectangles shrunk to fit --max-page
};

}  // namespace exitance
