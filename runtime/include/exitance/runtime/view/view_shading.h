// What one primary ray of exitance-view shows (docs/view.md, "What a pixel shows"): the radiance an
// engine would draw from the baked data at the first surface the ray meets, or the sky.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "exitance/runtime/vec_math.h"
#include "exitance/runtime/view/view_scene.h"

namespace exitance::view {

enum class ViewMode {
  Lightmap,  // albedo x lightmap E/pi (probes' E/pi where an instance has no texels) + emission; sky on a miss
  Probes,    // albedo x probes' E/pi for every surface + emission; sky on a miss
  Albedo,    // diffuse albedo; 0 on a miss
  Normal,    // shading normal * 0.5 + 0.5; 0 on a miss
  Error,     // the lightmap's error.Y channel (grey); 0 on a miss and where an instance has no texels
};

std::optional<ViewMode> parse_view_mode(const std::string& name);
const char* view_mode_name(ViewMode mode);

// The lightmap channel the error mode shows (written by bakes that estimate per-texel error).
inline constexpr const char* kErrorChannel = "error.Y";

// Per-thread scratch for the BVH walk.
struct RayScratch {
  std::vector<uint32_t> stack;
};

// The first surface a primary ray meets, as the view shades it.
struct SurfaceAtHit {
  Vec3 position;
  Vec3 geometric_normal;   // front side (counter-clockwise winding)
  Vec3 shading_normal;     // interpolated and normal-mapped, facing the viewer on a double-sided surface's back
  Vec3 interpolated_normal;  // front side, without the normal map: the n0 a lightmap texel was baked for
  Vec3 mapped_normal;        // front side, with the material's normal map (= interpolated_normal without one)
  bool back_face_absorbs;  // the back of a single-sided surface: the bake treats it as black
  uint32_t instance;
  uint32_t triangle;
  Vec3 albedo, emission;    // textured, COLOR_0 (view_materials.h)
  float opacity;            // 1 opaque; MASK 0 or 1; BLEND its coverage
  std::array<float, 2> lightmap_uv;
};

// The nearest surface along the ray from `origin` in unit `direction` that a ray does not pass
// through (MASK cut-outs and BLEND surfaces of coverage 0 are passed); std::nullopt on a miss.
std::optional<SurfaceAtHit> first_surface(const ViewScene& view, Vec3 origin, Vec3 direction, RayScratch& scratch);

// Radiance (or the debug quantity of `mode`) along the ray from `origin` in unit `direction`: BLEND
// surfaces composited front to back over what lies behind them, the sky (image or constant) on a
// miss in the lit modes.
Vec3 shade_primary_ray(const ViewScene& view, ViewMode mode, Vec3 origin, Vec3 direction, RayScratch& scratch);

}  // namespace exitance::view
