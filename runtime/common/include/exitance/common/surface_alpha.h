// glTF alphaMode for rays, shared by the CPU reference (runtime/src/alpha_coverage.cpp, Embree's
// filter functions) and the kernels' traversal (shaders/include/bvh.glsl): which hits stop a ray,
// and the per-ray, per-surface random number of BLEND's stochastic transparency.
#ifndef EXITANCE_COMMON_SURFACE_ALPHA_H
#define EXITANCE_COMMON_SURFACE_ALPHA_H
#include "exitance/common/dialect.h"
EXITANCE_NAMESPACE_BEGIN

// Alpha modes in the order of Material::AlphaMode (runtime/include/exitance/runtime/scene.h).
const uint kAlphaOpaque = 0u;
const uint kAlphaMask = 1u;
const uint kAlphaBlend = 2u;

// Coverage in [0, 1]; a non-finite product (a NaN texel) counts as opaque.
EXITANCE_FN float clamped_coverage(float coverage) {
  return (isnan(coverage) || isinf(coverage)) ? 1.0f : clamp(coverage, 0.0f, 1.0f);
}

// Whether a hit with this coverage stops the ray. `u` uniform in [0, 1) (BLEND only).
EXITANCE_FN bool coverage_stops_ray(uint alpha_mode, float coverage, float alpha_cutoff, float u) {
  if (alpha_mode == kAlphaMask) return coverage >= alpha_cutoff;
  if (alpha_mode == kAlphaBlend) return u < coverage;
  return true;
}

// Chris Wellons' lowbias32 (hash-prospector): every input bit reaches every output bit, in 32-bit
// arithmetic that GLSL computes exactly as C++.
EXITANCE_FN uint lowbias32(uint x) {
  x = x ^ (x >> 16u);
  x = x * 0x7feb352du;
  x = x ^ (x >> 15u);
  x = x * 0x846ca68bu;
  return x ^ (x >> 16u);
}

// A uniform number in [0, 1) from a ray and the triangle it met: the same ray meeting the same
// surface again (a traversal may report a hit twice) decides the same way; different rays
// independently.
EXITANCE_FN float blend_decision_number(vec3 origin, vec3 direction, uint triangle) {
  uint h = lowbias32(triangle + 0x9e3779b9u);
  h = lowbias32(h ^ floatBitsToUint(origin.x));
  h = lowbias32(h ^ floatBitsToUint(origin.y));
  h = lowbias32(h ^ floatBitsToUint(origin.z));
  h = lowbias32(h ^ floatBitsToUint(direction.x));
  h = lowbias32(h ^ floatBitsToUint(direction.y));
  h = lowbias32(h ^ floatBitsToUint(direction.z));
  return float(h >> 8u) * (1.0f / 16777216.0f);  // 24 bits: uniform in [0, 1)
}

EXITANCE_NAMESPACE_END
#endif
