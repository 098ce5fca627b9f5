// A map between the unit square and the hemisphere z >= 0 that preserves projected solid angle:
// Shirley & Chiu's concentric square -> disk map (area-preserving up to a constant), then Malley's
// projection of the disk up onto the hemisphere (xy kept, z = sqrt(1 - r^2)), as the cosine sampler
// of sampling.h does. Every region of the square of area A maps to directions of projected solid
// angle (integral of cos) pi A: a regular grid on the square is a set of bins of equal cosine
// mass, and a point uniform in a square cell has density cos / (pi * cell area) in its bin. So a
// piecewise-constant table of incident radiance sampled through this map is sampled in product with
// the diffuse cosine exactly, and a constant table is exactly cosine sampling.
#ifndef EXITANCE_COMMON_CONCENTRIC_HEMISPHERE_H
#define EXITANCE_COMMON_CONCENTRIC_HEMISPHERE_H
#include "exitance/common/sampling.h"
EXITANCE_NAMESPACE_BEGIN

// sin, cos and atan on the concentric map's wedges (|angle| <= pi/4, |x| <= 1) as Cephes' float
// polynomials (about 1e-7 relative): the same arithmetic in C++ and GLSL (whose built-ins differ
// between drivers), and a third of the cost of the library calls in a guided sample.
EXITANCE_FN float wedge_sin(float x) {
  float z = x * x;
  return ((-1.9515295891e-4f * z + 8.3321608736e-3f) * z - 1.6666654611e-1f) * z * x + x;
}
EXITANCE_FN float wedge_cos(float x) {
  float z = x * x;
  return ((2.443315711809948e-5f * z - 1.388731625493765e-3f) * z + 4.166664568298827e-2f) * z * z - 0.5f * z + 1.0f;
}
EXITANCE_FN float unit_atan(float x) {
  float ax = abs(x);
  float t = ax;
  float offset = 0.0f;
  if (ax > 0.41421356237309505f) {  // tan(pi/8): reduce to |t| <= tan(pi/8) around pi/4
    t = (ax - 1.0f) / (ax + 1.0f);
    offset = kPi / 4.0f;
  }
  float z = t * t;
  float r = offset + ((((8.05374449538e-2f * z - 1.38776856032e-1f) * z + 1.99777106478e-1f) * z - 3.33329491539e-1f) * z * t + t);
  return x < 0.0f ? -r : r;
}

EXITANCE_FN vec3 concentric_square_to_hemisphere(float s, float t) {
  float a = 2.0f * s - 1.0f;
  float b = 2.0f * t - 1.0f;
  float x = 0.0f;
  float y = 0.0f;
  if (a * a > b * b) {  // wedge around the x axis: angle pi/4 * b/a
    float angle = (kPi / 4.0f) * (b / a);
    x = a * wedge_cos(angle);
    y = a * wedge_sin(angle);
  } else if (b != 0.0f) {  // around the y axis: angle pi/2 - pi/4 * a/b
    float angle = (kPi / 4.0f) * (a / b);
    x = b * wedge_sin(angle);
    y = b * wedge_cos(angle);
  }
  return vec3(x, y, sqrt(max(0.0f, 1.0f - x * x - y * y)));
}

// The inverse, for unit d (only d.xy is read: the disk point); the result lies in [0, 1]^2. Unit
// length is not checked: a slightly long d gives a point just inside the square.
EXITANCE_FN vec2 hemisphere_to_concentric_square(vec3 d) {
  float r = min(sqrt(d.x * d.x + d.y * d.y), 1.0f);
  float a = 0.0f;
  float b = 0.0f;
  float ax = abs(d.x);
  float ay = abs(d.y);
  if (ax >= ay && ax > 0.0f) {
    a = d.x < 0.0f ? -r : r;
    b = a * (4.0f / kPi) * unit_atan(d.y / d.x);
  } else if (ay > 0.0f) {
    b = d.y < 0.0f ? -r : r;
    a = b * (4.0f / kPi) * unit_atan(d.x / d.y);
  }
  return vec2(clamp(0.5f * (a + 1.0f), 0.0f, 1.0f), clamp(0.5f * (b + 1.0f), 0.0f, 1.0f));
}

EXITANCE_NAMESPACE_END
#endif
