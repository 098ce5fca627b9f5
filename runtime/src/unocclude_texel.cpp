#include "exitance/runtime/unocclude_texel.h"

#include <cmath>

#include "exitance/common/ray_offset.h"
#include "exitance/common/sampling.h"

namespace exitance {

bool unocclude_texel(LiveTexel& texel, float scene_extent, const ClosestHitQuery& closest_hit) {
  constexpr int kDirections = 8;
  const float reach = unocclude_reach(texel);
  if (!(reach > 0)) return false;
  Vec3 t, b;
  orthonormal_basis(texel.geometric_normal, t, b);
  // Start a hair above the surface; look sideways, tilted slightly up, within the texel footprint.
  const Vec3 origin = offset_ray_origin(texel.position, texel.geometric_normal, scene_extent);
  float closest = reach;
  Vec3 push_to{};
  bool push = false;
  for (int k = 0; k < kDirections; ++k) {
    const float phi = 2.0f * kPi * (float(k) + 0.5f) / float(kDirections);
    const Vec3 dir = normalize(t * std::cos(phi) + b * std::sin(phi) + texel.geometric_normal * 0.05f);
    const OccluderHit hit = closest_hit(origin, dir, closest);
    if (!hit.found) continue;
    closest = hit.distance;
    // Seeing a back face this close means the centre sits inside or behind that surface.
    push = dot(dir, hit.geometric_normal) > 0;
    if (push) {
      const Vec3 p = origin + dir * hit.distance;
      const Vec3 beyond = offset_ray_origin(p, hit.geometric_normal, scene_extent);  // just past the back face
      push_to = beyond + dir * (texel.world_texel_size * 0.01f);
    }
  }
  if (!push) return false;
  // Keep the texel on its own plane: drop the tilt we added along the normal.
  const float height = dot(push_to - texel.position, texel.geometric_normal);
  texel.position = push_to - texel.geometric_normal * height;
  return true;
}

}  // namespace exitance
