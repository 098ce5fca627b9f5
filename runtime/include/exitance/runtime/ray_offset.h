// Robust ray origins: Wächter & Binder, "A Fast and Robust Method for Avoiding
// Self-Intersection", Ray Tracing Gems ch. 6. Offsets scale with the magnitude of the
// position, so geometry far from the origin does not self-intersect.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>

#include "exitance/runtime/vec_math.h"

namespace exitance {

inline float offset_component(float p, float n) {
  constexpr float kOrigin = 1.0f / 32.0f;
  constexpr float kFloatScale = 1.0f / 65536.0f;
  constexpr float kIntScale = 256.0f;
  const int32_t of_i = int32_t(kIntScale * n);
  int32_t bits;
  std::memcpy(&bits, &p, 4);
  bits += (p < 0) ? -of_i : of_i;
  float p_i;
  std::memcpy(&p_i, &bits, 4);
  return std::fabs(p) < kOrigin ? p + kFloatScale * n : p_i;
}

// Moves p off the surface along n (pass -n to leave through the back side).
inline Vec3 offset_ray_origin(Vec3 p, Vec3 n) {
  return {offset_component(p.x, n.x), offset_component(p.y, n.y), offset_component(p.z, n.z)};
}

}  // namespace exitance
