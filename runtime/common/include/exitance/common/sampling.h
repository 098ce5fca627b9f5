// Sampling routines shared by every integrator and kernel.
#ifndef EXITANCE_COMMON_SAMPLING_H
#define EXITANCE_COMMON_SAMPLING_H
#include "exitance/common/vector_functions.h"
EXITANCE_NAMESPACE_BEGIN

const float kPi = 3.14159265358979323846f;
const float kInvPi = 0.31830988618379067154f;

// Concentric disk mapping (Shirley & Chiu 1997), then Malley's method: pdf = cos(theta) / pi.
EXITANCE_FN vec3 sample_cosine_hemisphere(float u1, float u2) {
  float a = 2.0f * u1 - 1.0f;
  float b = 2.0f * u2 - 1.0f;
  float r = 0.0f;
  float phi = 0.0f;
  if (a != 0.0f || b != 0.0f) {
    if (a * a > b * b) {
      r = a;
      phi = (kPi / 4.0f) * (b / a);
    } else {
      r = b;
      phi = (kPi / 2.0f) - (kPi / 4.0f) * (a / b);
    }
  }
  float x = r * cos(phi);
  float y = r * sin(phi);
  return vec3(x, y, sqrt(max(0.0f, 1.0f - x * x - y * y)));
}

// Uniform over the hemisphere z >= 0: pdf = 1 / (2 pi).
EXITANCE_FN vec3 sample_uniform_hemisphere(float u1, float u2) {
  float z = u1;
  float r = sqrt(max(0.0f, 1.0f - z * z));
  float phi = 2.0f * kPi * u2;
  return vec3(r * cos(phi), r * sin(phi), z);
}

EXITANCE_FN vec3 to_world(vec3 local, vec3 n) {
  vec3 t;
  vec3 b;
  orthonormal_basis(n, t, b);
  return t * local.x + b * local.y + n * local.z;
}

// u in [lo, lo + width) rescaled to [0, 1): a one-sample mixture's choice number reused as the
// chosen component's own number, so the component keeps the sampler's stratification.
EXITANCE_FN float rescaled_unit(float u, float lo, float width) {
  return min(max((u - lo) / width, 0.0f), 0.99999994f);
}

// Uniform point on a triangle (Heitz 2019, "A Low-Distortion Map Between Triangle and Square"):
// barycentrics (b1, b2) of vertices 1 and 2.
EXITANCE_FN vec2 sample_triangle_barycentrics(float u1, float u2) {
  if (u2 > u1) {
    float b1 = u1 * 0.5f;
    return vec2(b1, u2 - b1);
  }
  float b2 = u2 * 0.5f;
  return vec2(u1 - b2, b2);
}

EXITANCE_FN vec3 uniform_sphere(float u1, float u2) {
  float z = 1.0f - 2.0f * u1;
  float r = sqrt(max(0.0f, 1.0f - z * z));
  float phi = 2.0f * kPi * u2;
  return vec3(r * cos(phi), r * sin(phi), z);
}

// Direction of probe sample `index` out of `count`: the first m*m samples (m = floor(sqrt(count)))
// are stratified over an m x m grid of the equal-area (z, phi) square, one jittered sample per
// cell; the rest are uniform.
EXITANCE_FN vec3 probe_direction(uint index, uint count, float u1, float u2) {
  uint m = uint(sqrt(float(count)));
  while ((m + 1u) * (m + 1u) <= count) ++m;
  while (m > 0u && m * m > count) --m;
  if (index < m * m) {
    float inv = 1.0f / float(m);
    u1 = (float(index % m) + u1) * inv;
    u2 = (float(index / m) + u2) * inv;
  }
  return uniform_sphere(min(u1, 0.99999994f), min(u2, 0.99999994f));
}

// Power heuristic with beta = 2 (Veach 1997) for one sample from each of two strategies.
EXITANCE_FN float power_heuristic(float pdf_a, float pdf_b) {
  float a = pdf_a * pdf_a;
  float b = pdf_b * pdf_b;
  if (!(a > 0.0f)) return 0.0f;
  if (isinf(a)) return 1.0f;
  return a / (a + b);
}

EXITANCE_NAMESPACE_END
#endif
