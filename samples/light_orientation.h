// glTF punctual lights shine along their node's local −Z axis; this gives the
// node rotation that turns −Z onto a wanted direction.
#pragma once

#include <array>
#include <cmath>

#include "vec3.h"

namespace exitance::samples {

// Unit quaternion [x, y, z, w] (glTF order) of the shortest rotation taking −Z to
// `direction` (any non-zero length).
inline std::array<double, 4> rotationFromMinusZ(Vec3 direction) {
  const Vec3 d = normalize(direction);
  // Shortest arc from a = −Z: q = (a × d, 1 + a·d), normalised.
  const double w = 1.0 - double(d.z);
  if (w < 1e-9) return {0.0, 1.0, 0.0, 0.0};  // d = +Z: half turn about Y
  const double x = d.y, y = -double(d.x);
  const double norm = std::sqrt(x * x + y * y + w * w);
  return {x / norm, y / norm, 0.0, w / norm};
}

}  // namespace exitance::samples
