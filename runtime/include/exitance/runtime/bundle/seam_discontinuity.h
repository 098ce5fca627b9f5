// How visible the seams are: the mean over seam samples of |A - B| / ((A + B) / 2), A and B the
// bilinear luminance of the final lightmap (R, G, B) at the sample on either side. Samples where
// both sides are black are left out (no relative difference).
#pragma once
#include <cstddef>
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

// The same measure page by page, for pages assembled one at a time: page(p, image) for every page in
// ascending order, then result() is measure_seam_discontinuity's (the same sums in the same order).
// `samples` must outlive the meter.
class SeamDiscontinuityMeter {
 public:
  explicit SeamDiscontinuityMeter(const std::vector<SeamSample>& samples);
  void page(size_t p, const formats::LightmapImage& image);
  SeamDiscontinuity result() const;

 private:
  const std::vector<SeamSample>& samples_;
  std::vector<std::vector<size_t>> on_page_;  // sample indices per page, ascending
  std::vector<double> difference_;            // per sample; NaN where not counted
  double error_sum_ = 0;
  size_t covered_ = 0;
};

}  // namespace exitance
