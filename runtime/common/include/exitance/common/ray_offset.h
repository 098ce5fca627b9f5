// Robust ray origins from a bound on the position's rounding error (pbrt-v4 §6.8.6).
// Positions are interpolated from barycentrics, whose error is at most gamma(7) * sum |b_i p_i|
// (~4.2e-7 |p|, 3.5 ulps); we offset by that along the normal, plus a floor relative to the
// scene size for points near the origin, then round away from the surface by one ulp.
//
// Why not Wächter & Binder (Ray Tracing Gems ch. 6): its fixed 256-ulp offset is ~3e-5 |p|,
// i.e. 3 units for geometry 1e5 from the origin, which pushes texels through walls; and its
// absolute 1/65536 offset near the origin exceeds the gaps of millimetre-scale scenes. Both
// failed the stress tests (tests/stress), this bound passes them.
#ifndef EXITANCE_COMMON_RAY_OFFSET_H
#define EXITANCE_COMMON_RAY_OFFSET_H
#include "exitance/common/dialect.h"
EXITANCE_NAMESPACE_BEGIN

const float kRelativePositionError = 4.2e-7f;  // gamma(7) = 7u / (1 - 7u), u = 2^-24
const float kScenePositionErrorFloor = 1e-6f;  // times the scene's extent

// The next float from x in the direction of `direction`'s sign (x itself for 0): nextafter on the bits.
EXITANCE_FN float next_float_toward(float x, float direction) {
  if (direction == 0.0f) return x;
  if (x == 0.0f) return direction > 0.0f ? uintBitsToFloat(1u) : -uintBitsToFloat(1u);
  uint bits = floatBitsToUint(x);
  bool away = (x > 0.0f) == (direction > 0.0f);  // away from zero: one more in the magnitude's bits
  return uintBitsToFloat(away ? bits + 1u : bits - 1u);
}

// Moves p off the surface along the unit normal n (pass -n to leave through the back side).
// `scene_extent` is the size of the scene's bounding box (its largest side).
EXITANCE_FN vec3 offset_ray_origin(vec3 p, vec3 n, float scene_extent) {
  float floor_error = kScenePositionErrorFloor * scene_extent;
  vec3 error = abs(p) * kRelativePositionError + vec3(floor_error);
  vec3 an = abs(n);
  float distance = an.x * error.x + an.y * error.y + an.z * error.z;
  vec3 moved = p + n * distance;
  return vec3(next_float_toward(moved.x, n.x), next_float_toward(moved.y, n.y), next_float_toward(moved.z, n.z));
}

EXITANCE_NAMESPACE_END
#endif
