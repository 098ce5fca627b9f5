// Sampling routines shared by every integrator (and, later, the shaders).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "exitance/runtime/vec_math.h"

namespace exitance {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 0.31830988618379067154f;

// Concentric disk mapping (Shirley & Chiu 1997), then Malley's method: pdf = cos(theta) / pi.
inline Vec3 sample_cosine_hemisphere(float u1, float u2) {
  const float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
  float r = 0.0f, phi = 0.0f;
  if (a != 0.0f || b != 0.0f) {
    if (a * a > b * b) { r = a; phi = (kPi / 4.0f) * (b / a); }
    else { r = b; phi = (kPi / 2.0f) - (kPi / 4.0f) * (a / b); }
  }
  const float x = r * std::cos(phi), y = r * std::sin(phi);
  return {x, y, std::sqrt(std::max(0.0f, 1.0f - x * x - y * y))};
}

inline Vec3 to_world(Vec3 local, Vec3 n) {
  Vec3 t, b;
  orthonormal_basis(n, t, b);
  return t * local.x + b * local.y + n * local.z;
}

// Uniform point on a triangle (Heitz 2019, "A Low-Distortion Map Between Triangle and Square"):
// returns barycentrics (b1, b2) of vertices 1 and 2.
inline void sample_triangle_barycentrics(float u1, float u2, float& b1, float& b2) {
  if (u2 > u1) {
    b1 = u1 * 0.5f;
    b2 = u2 - b1;
  } else {
    b2 = u2 * 0.5f;
    b1 = u1 - b2;
  }
}

inline Vec3 uniform_sphere(float u1, float u2) {
  const float z = 1.0f - 2.0f * u1;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Direction of probe sample `index` out of `count`: the first m*m samples (m = floor(sqrt(count)))
// are stratified over an m x m grid of the equal-area (z, phi) square, one jittered sample per
// cell; the rest are uniform. Probe rays and their SH projection use it on both backends.
inline Vec3 probe_direction(uint32_t index, uint32_t count, float u1, float u2) {
  uint32_t m = uint32_t(std::sqrt(float(count)));
  while ((m + 1) * (m + 1) <= count) ++m;
  while (m > 0 && m * m > count) --m;
  if (index < m * m) {
    const float inv = 1.0f / float(m);
    u1 = (float(index % m) + u1) * inv;
    u2 = (float(index / m) + u2) * inv;
  }
  return uniform_sphere(std::min(u1, 0.99999994f), std::min(u2, 0.99999994f));
}

// Power heuristic with beta = 2 (Veach 1997) for one sample from each of two strategies.
inline float power_heuristic(float pdf_a, float pdf_b) {
  const float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  if (!(a > 0.0f)) return 0.0f;
  if (!std::isfinite(a)) return 1.0f;
  return a / (a + b);
}

}  // namespace exitance
