// Robust ray origins from a bound on the position's rounding error (pbrt-v4 §6.8.6).
// Positions are interpolated from barycentrics, whose error is at most gamma(7) * sum |b_i p_i|
// (~4.2e-7 |p|, 3.5 ulps); we offset by that along the normal, plus a floor relative to the
// scene size for points near the origin, then round away from the surface by one ulp.
//
// Why not Wächter & Binder (Ray Tracing Gems ch. 6): its fixed 256-ulp offset is ~3e-5 |p|,
// i.e. 3 units for geometry 1e5 from the origin, which pushes texels through walls; and its
// absolute 1/65536 offset near the origin exceeds the gaps of millimetre-scale scenes. Both
// failed the stress tests (tests/stress), this bound passes them.
#pragma once
#include <cmath>

#include "exitance/runtime/vec_math.h"

namespace exitance {

constexpr float kRelativePositionError = 4.2e-7f;  // gamma(7) = 7u / (1 - 7u), u = 2^-24
constexpr float kScenePositionErrorFloor = 1e-6f;  // times the scene's extent

inline float next_float_toward(float x, float direction) {
  if (direction > 0) return std::nextafter(x, INFINITY);
  if (direction < 0) return std::nextafter(x, -INFINITY);
  return x;
}

// Moves p off the surface along the unit normal n (pass -n to leave through the back side).
// `scene_extent` is the size of the scene's bounding box (its largest side).
inline Vec3 offset_ray_origin(Vec3 p, Vec3 n, float scene_extent) {
  const float floor = kScenePositionErrorFloor * scene_extent;
  const Vec3 error{kRelativePositionError * std::fabs(p.x) + floor, kRelativePositionError * std::fabs(p.y) + floor,
                   kRelativePositionError * std::fabs(p.z) + floor};
  const float distance = std::fabs(n.x) * error.x + std::fabs(n.y) * error.y + std::fabs(n.z) * error.z;
  const Vec3 moved = p + n * distance;
  return {next_float_toward(moved.x, n.x), next_float_toward(moved.y, n.y), next_float_toward(moved.z, n.z)};
}

}  // namespace exitance
