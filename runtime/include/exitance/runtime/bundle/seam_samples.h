// Points along seam edges, paired across the seam, and the bilinear taps a lookup at a point reads:
// what the seam stitching solves over and what its discontinuity measure reads.
#pragma once
#include <array>
#include <cstddef>
#include <vector>

#include "exitance/runtime/bundle/seam_detection.h"

namespace exitance {

// One 3-D point on a seam: where each side's chart maps it, in texel coordinates of `page`.
struct SeamSample {
  int page = 0;
  Vec2 side_a, side_b;
};

// Evenly spaced points (segment midpoints) along every edge, samples_per_texel per texel of the
// longer side's length, at least one per edge.
std::vector<SeamSample> seam_samples(const std::vector<SeamEdge>& seams, float samples_per_texel);

// The four texels and weights the loader's bilinear lookup (runtime/loader/src/lightmap_lookup.cpp)
// reads at a texel-coordinate point: texel centres at integer + 0.5, clamp to edge.
struct BilinearTaps {
  std::array<size_t, 4> texel;
  std::array<double, 4> weight;
};
BilinearTaps bilinear_taps(int width, int height, Vec2 point);

}  // namespace exitance
