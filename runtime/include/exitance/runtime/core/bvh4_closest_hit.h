// Closest hit on the lighting scene's BVH4 on the CPU, without Embree: what the runtime uses for
// the few rays it casts on the host (unocclude near a moved instance). Double-precision
// Moller-Trumbore per triangle; not the GPU's watertight test, so on an edge or a vertex it may
// report the other triangle (nothing here depends on which).
#pragma once
#include <cstdint>

#include "exitance/runtime/core/lighting_scene.h"

namespace exitance {

struct BvhHit {
  bool found = false;
  float distance = 0;
  uint32_t triangle = 0;
  Vec3 geometric_normal;  // unit, normalize(cross(p1 - p0, p2 - p0)): the front side
};

// The nearest triangle hit at a distance in (0, t_max].
BvhHit closest_hit(const LightingScene& scene, const Vec3& origin, const Vec3& direction, float t_max);

}  // namespace exitance
