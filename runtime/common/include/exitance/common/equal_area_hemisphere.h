// An equal-area map between the unit square and the hemisphere z >= 0: Shirley & Chiu's
// concentric square -> disk map (area-preserving up to a constant), then Lambert's azimuthal
// equal-area projection of the disk onto the hemisphere (z = 1 - r^2, xy scaled by sqrt(2 - r^2)).
// Every region of the square of area A maps to a solid angle 2 pi A, so a regular grid on the square
// is a set of equal-solid-angle bins and a point uniform in a square cell is uniform in its bin.
#ifndef EXITANCE_COMMON_EQUAL_AREA_HEMISPHERE_H
#define EXITANCE_COMMON_EQUAL_AREA_HEMISPHERE_H
#include "exitance/common/sampling.h"
EXITANCE_NAMESPACE_BEGIN

const float kHemisphereSolidAngle = 6.28318530717958647692f;

EXITANCE_FN vec3 equal_area_square_to_hemisphere(float s, float t) {
  float a = 2.0f * s - 1.0f;
  float b = 2.0f * t - 1.0f;
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
  float r2 = min(x * x + y * y, 1.0f);
  float scale = sqrt(2.0f - r2);
  return vec3(x * scale, y * scale, 1.0f - r2);
}

// The inverse, for unit d with d.z >= 0 (d.z < 0 is treated as the equator); the result lies in
// [0, 1]^2. Unit length is not checked: a slightly long d gives a point just inside the square.
EXITANCE_FN vec2 equal_area_hemisphere_to_square(vec3 d) {
  float z = clamp(d.z, 0.0f, 1.0f);
  float r = sqrt(1.0f - z);  // disk radius
  float planar = sqrt(d.x * d.x + d.y * d.y);
  float a = 0.0f;
  float b = 0.0f;
  if (planar > 0.0f && r > 0.0f) {
    float phi = atan(d.y, d.x);  // (-pi, pi]
    if (phi < -kPi / 4.0f) phi += 2.0f * kPi;  // [-pi/4, 7pi/4): the four wedges of the concentric map
    if (phi < kPi / 4.0f) {
      a = r;
      b = r * phi * (4.0f / kPi);
    } else if (phi < 3.0f * kPi / 4.0f) {
      b = r;
      a = r * (kPi / 2.0f - phi) * (4.0f / kPi);
    } else if (phi < 5.0f * kPi / 4.0f) {
      a = -r;
      b = -r * (phi - kPi) * (4.0f / kPi);
    } else {
      b = -r;
      a = -r * (3.0f * kPi / 2.0f - phi) * (4.0f / kPi);
    }
  }
  return vec2(clamp(0.5f * (a + 1.0f), 0.0f, 1.0f), clamp(0.5f * (b + 1.0f), 0.0f, 1.0f));
}

EXITANCE_NAMESPACE_END
#endif
