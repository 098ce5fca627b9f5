// Minimal 3-vector for the scene generators. The samples only need a handful of
// operations, so a dependency on a maths library would cost more than it saves.
#pragma once

#include <cmath>

namespace exitance::samples {

struct Vec3 {
  float x = 0.0f, y = 0.0f, z = 0.0f;

  friend Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
  friend Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
  friend Vec3 operator*(float s, Vec3 a) { return a * s; }
  friend bool operator==(Vec3, Vec3) = default;
};

inline float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(Vec3 a) { return std::sqrt(dot(a, a)); }
inline Vec3 normalize(Vec3 a) { return a * (1.0f / length(a)); }

// Right-handed rotation about +Y by `radians` (turns +Z towards +X).
inline Vec3 rotateAboutY(Vec3 a, float radians) {
  const float c = std::cos(radians), s = std::sin(radians);
  return {c * a.x + s * a.z, a.y, -s * a.x + c * a.z};
}

}  // namespace exitance::samples
