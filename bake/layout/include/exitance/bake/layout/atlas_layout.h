// One rectangle per mesh instance, packed into atlas pages (shelf packing, tallest first). The
// InstanceRect and AtlasLayout types are in exitance/runtime/lightmap_atlas.h (scene.bin restores them).
#pragma once
#include <vector>

#include "exitance/bake/diagnostics.h"
#include "exitance/runtime/lightmap_atlas.h"
#include "exitance/runtime/scene.h"

namespace exitance {

struct AtlasSettings {
  float texel_density = 0;  // texels per scene unit; <= 0 = automatic
  int max_page = 2048;      // page size limit in texels
  int padding = 2;          // texels of gutter around every rectangle
  size_t max_total_texels = size_t(16) << 20;  // automatic density never exceeds this many texels
};

AtlasLayout layout_lightmap_atlas(const Scene& scene, const AtlasSettings& settings, const std::string& file,
                                  Diagnostics& diagnostics);

// The density bake uses when the user gives none: 64 texels per unit for a room-sized scene,
// lowered for large scenes so the atlas stays under `max_total_texels`.
float automatic_texel_density(const Scene& scene, size_t max_total_texels);

}  // namespace exitance
