// How visible the seams are: the mean over seam samples of |A - B| / ((A + B) / 2), A and B the
// bilinear luminance of the final lightmap (R, G, B) at the sample on either side. Samples where
// both sides are black are left out (no relative difference).
#pragma once
#include <vector>

#include "exitance/runtime/bundle/seam_samples.h"
#include "exitance/formats/lightmap_exr.h"

namespace exitance {

struct SeamDiscontinuity {
  double mean_relative_difference = 0;  // 0 when no sample counted
  size_t samples = 0;                   // samples counted
  // The noise to compare with: the mean error.Y (each texel's relative standard error) over the
  // covered texels the samples' lookups read; 0 when the pages have no error.Y.
  double mean_texel_relative_error = 0;
};

SeamDiscontinuity measure_seam_discontinuity(const std::vector<formats::LightmapImage>& pages,
                                             const std::vector<SeamSample>& samples);

}  // namespace exitance
