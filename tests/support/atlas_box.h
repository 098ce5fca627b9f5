// The unit box with inward faces on a real atlas (layout + texel raster, so gathers and guiding
// see real texels): each face its own instance (its own chart), emission[f] for face f (floor,
// ceiling, back, front, left, right), and optionally a small emitter of side `light_side` and
// radiance `light_le` just under the ceiling's centre.
#pragma once
#include <string>

#include "exitance/bake/layout/atlas_layout.h"
#include "exitance/bake/raster/texel_raster.h"
#include "support/analytic_scenes.h"

namespace exitance::testing {

struct AtlasScene {
  Scene scene;
  TexelGBuffer gbuffer;
};

inline AtlasScene atlas_box(float albedo, const Vec3 (&emission)[6], float density, float light_side = 0,
                            Vec3 light_le = {}) {
  AtlasScene a;
  const Vec3 ex{1, 0, 0}, ey{0, 1, 0}, ez{0, 0, 1}, o{0, 0, 0};
  const Vec3 corner[6] = {o, ey, o, ez, o, ex};
  const Vec3 u[6] = {ez, ex, ex, ey, ey, ez};
  const Vec3 v[6] = {ex, ez, ey, ex, ez, ey};
  for (int f = 0; f < 6; ++f) {
    add_quad(a.scene, corner[f], u[f], v[f], add_material(a.scene, {albedo, albedo, albedo}, emission[f]));
    a.scene.instances.back().name = "face" + std::to_string(f);
  }
  if (light_side > 0) {
    const float lo = 0.5f - light_side / 2;
    add_quad(a.scene, {lo, 0.999f, lo}, ex * light_side, ez * light_side, add_material(a.scene, {0, 0, 0}, light_le));
    a.scene.instances.back().name = "light";
  }
  AtlasSettings atlas;
  atlas.texel_density = density;
  Diagnostics diagnostics;
  const AtlasLayout layout = layout_lightmap_atlas(a.scene, atlas, "box", diagnostics);
  a.gbuffer = rasterize_texel_gbuffer(a.scene, layout, "box", diagnostics);
  return a;
}

}  // namespace exitance::testing
