// The directional part of the grid guiding cache (seed 002, issue 11): per (spatial cell, normal
// class) a hemisphere of kGuideBinsPerSide^2 bins of equal cosine mass (concentric_hemisphere.h)
// holding piecewise-constant incident radiance, sampled in product with the cosine: a bin by
// inverting its CDF (O(log N), exact, no rejection loop), then a point uniform in the bin's square
// cell, which has density proportional to cos inside the bin (the thesis's Alg. 2 never jitters
// inside a bin). pdf(w) = P(bin) * kGuideBins * cos / pi; a constant table is cosine sampling.
//
// Normal classes: the six axis directions. A vertex takes the class of its normal's largest
// component, and the class's hemisphere is laid out in a fixed axis frame, so a cell's walls of
// opposite orientation learn apart and a texel's distribution never needs a per-normal CDF (the
// thesis clips a full-sphere table to each normal's hemisphere, O(N) per vertex). Directions of the
// class hemisphere under a tilted surface are wasted samples, not bias: the pdf is exact either way.
//
// The CDF is read through guide_cdf_at(GUIDE_CDF_REF, i) (C++: a pointer; GLSL: defined by the
// includer over its buffer), as distribution.h reads its CDFs.
#ifndef EXITANCE_COMMON_GUIDED_DIRECTION_H
#define EXITANCE_COMMON_GUIDED_DIRECTION_H
#include "exitance/common/concentric_hemisphere.h"

#ifdef __cplusplus
#define GUIDE_CDF_REF const float*
#define GUIDE_CDF_NONE nullptr
namespace exitance {
inline float guide_cdf_at(const float* cdf, uint i) { return cdf[i]; }
}  // namespace exitance
#else
#define GUIDE_CDF_REF uint
#define GUIDE_CDF_NONE 0u
#endif

EXITANCE_NAMESPACE_BEGIN

const uint kGuideBinsPerSide = 16u;
const uint kGuideBins = 256u;  // kGuideBinsPerSide^2
const uint kGuideNormalClasses = 6u;

// The guided strategy at one path vertex: what the cache's frozen (front) table says there.
struct GuideVertex {
  float guided_probability;  // of the guided component in the one-sample mixture; 0: cosine only
  uint normal_class;         // guide_normal_class of the vertex's shading normal
  GUIDE_CDF_REF cdf;         // kGuideBins + 1 values, cdf[0] = 0, cdf[kGuideBins] = 1, non-decreasing
  // Defensive uniform-hemisphere component (path.h): the strategy above is taken with probability
  // 1 - uniform_probability. Non-zero only at texels of directional bakes; 0: none.
  float uniform_probability;
};

// Class 2a + (n[a] < 0) for the axis a of the largest |component| (ties: the lower axis).
EXITANCE_FN uint guide_normal_class(vec3 n) {
  float ax = abs(n.x);
  float ay = abs(n.y);
  float az = abs(n.z);
  uint axis = 0u;
  if (ay > ax) axis = 1u;
  if (az > max(ax, ay)) axis = 2u;
  float component = axis == 0u ? n.x : (axis == 1u ? n.y : n.z);
  return 2u * axis + (component < 0.0f ? 1u : 0u);
}

// World direction -> the class frame (t, b, n) = (e[a+1], e[a+2], +-e[a]), and back.
EXITANCE_FN vec3 guide_to_class_local(uint normal_class, vec3 w) {
  uint axis = normal_class / 2u;
  float sign = (normal_class & 1u) != 0u ? -1.0f : 1.0f;
  if (axis == 0u) return vec3(w.y, w.z, sign * w.x);
  if (axis == 1u) return vec3(w.z, w.x, sign * w.y);
  return vec3(w.x, w.y, sign * w.z);
}
EXITANCE_FN vec3 guide_from_class_local(uint normal_class, vec3 l) {
  uint axis = normal_class / 2u;
  float sign = (normal_class & 1u) != 0u ? -1.0f : 1.0f;
  if (axis == 0u) return vec3(sign * l.z, l.x, l.y);
  if (axis == 1u) return vec3(l.y, sign * l.z, l.x);
  return vec3(l.x, l.y, sign * l.z);
}

// The bin of a class-local direction with z > 0: row-major over the equal-area square.
EXITANCE_FN uint guide_bin_of_local(vec3 local) {
  vec2 st = hemisphere_to_concentric_square(local);
  uint i = min(uint(st.x * float(kGuideBinsPerSide)), kGuideBinsPerSide - 1u);
  uint j = min(uint(st.y * float(kGuideBinsPerSide)), kGuideBinsPerSide - 1u);
  return j * kGuideBinsPerSide + i;
}

// The class-local direction at square coordinates (fx, fy) in [0, 1)^2 of bin `bin`.
EXITANCE_FN vec3 guide_bin_point(uint bin, float fx, float fy) {
  float inv = 1.0f / float(kGuideBinsPerSide);
  float s = min((float(bin % kGuideBinsPerSide) + fx) * inv, 0.99999994f);
  float t = min((float(bin / kGuideBinsPerSide) + fy) * inv, 0.99999994f);
  return concentric_square_to_hemisphere(s, t);
}

EXITANCE_FN float guide_bin_probability(GUIDE_CDF_REF cdf, uint bin) {
  return max(guide_cdf_at(cdf, bin + 1u) - guide_cdf_at(cdf, bin), 0.0f);
}

// CDF inversion: the bin k with cdf[k] <= u < cdf[k + 1] (u exactly on an edge opens the bin
// above it), then back over bins of probability 0 so a plateau never returns an impossible bin.
// The search has a fixed number of steps without data-dependent branches (a select per step): the
// branchy version mispredicted on every step and cost a third of a guided sample.
EXITANCE_FN uint guide_sample_bin(GUIDE_CDF_REF cdf, float u) {
  uint bin = 0u;  // largest k with cdf[k] <= u, k in [0, kGuideBins - 1]
  for (uint step = kGuideBins / 2u; step > 0u; step /= 2u) bin = guide_cdf_at(cdf, bin + step) <= u ? bin + step : bin;
  while (bin > 0u && !(guide_bin_probability(cdf, bin) > 0.0f)) --bin;
  return bin;
}

// The guided component's solid-angle density at world direction wi (0 outside the class hemisphere).
EXITANCE_FN float guided_component_pdf(GuideVertex g, vec3 wi) {
  vec3 local = guide_to_class_local(g.normal_class, wi);
  if (!(local.z > 0.0f)) return 0.0f;
  return guide_bin_probability(g.cdf, guide_bin_of_local(local)) * float(kGuideBins) * local.z * kInvPi;
}

// A world direction from the guided component, from two numbers: u_bin picks the bin by CDF
// inversion and its remainder inside the bin's CDF interval (uniform in [0, 1) given the bin) places
// the point along the bin's square cell, u_y across it. One 2-D sample in, so the sampler's 2-D
// stratification carries through the warp. Both coordinates are kept kGuideEdgeMargin inside the
// cell: a point exactly on its edge (u_bin equal to a CDF value, u_y = 0: both happen with dyadic
// samples) can round into the neighbouring bin on the way through the concentric map and back, whose
// probability may be 0. The margin moves 2^-20 of a bin's mass by at most 2^-20 of its width, below
// the CDF's own float rounding.
const float kGuideEdgeMargin = 9.5367431640625e-7f;  // 2^-20
EXITANCE_FN float guide_inside_cell(float f) {
  return kGuideEdgeMargin + min(max(f, 0.0f), 1.0f) * (1.0f - 2.0f * kGuideEdgeMargin);
}
EXITANCE_FN vec3 guided_component_sample(GuideVertex g, float u_bin, float u_y) {
  uint bin = guide_sample_bin(g.cdf, u_bin);
  float probability = guide_bin_probability(g.cdf, bin);
  float fx = probability > 0.0f ? (u_bin - guide_cdf_at(g.cdf, bin)) / probability : 0.5f;
  return guide_from_class_local(g.normal_class, guide_bin_point(bin, guide_inside_cell(fx), guide_inside_cell(u_y)));
}

EXITANCE_NAMESPACE_END
#endif
