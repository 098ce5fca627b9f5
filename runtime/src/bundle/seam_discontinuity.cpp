#include "exitance/runtime/bundle/seam_discontinuity.h"

#include <cmath>
#include <set>
#include <utility>

namespace exitance {
namespace {

double bilinear_luminance(const formats::LightmapImage& page, Vec2 point) {
  const BilinearTaps taps = bilinear_taps(page.width, page.height, point);
  const std::vector<float>& r = page.channels.at("R");
  const std::vector<float>& g = page.channels.at("G");
  const std::vector<float>& b = page.channels.at("B");
  double y = 0;
  for (int k = 0; k < 4; ++k) {
    const size_t i = taps.texel[size_t(k)];
    y += taps.weight[size_t(k)] * (0.2126 * r[i] + 0.7152 * g[i] + 0.0722 * b[i]);
  }
  return y;
}

}  // namespace

SeamDiscontinuityMeter::SeamDiscontinuityMeter(const std::vector<SeamSample>& samples)
    : samples_(samples), difference_(samples.size(), std::nan("")) {
  for (size_t k = 0; k < samples.size(); ++k) {
    if (samples[k].page < 0) continue;
    if (on_page_.size() <= size_t(samples[k].page)) on_page_.resize(size_t(samples[k].page) + 1);
    on_page_[size_t(samples[k].page)].push_back(k);
  }
}

void SeamDiscontinuityMeter::page(size_t p, const formats::LightmapImage& image) {
  if (p >= on_page_.size() || !image.channels.count("R")) return;
  std::set<size_t> seam_texels;
  for (size_t k : on_page_[p]) {
    const SeamSample& s = samples_[k];
    const double a = bilinear_luminance(image, s.side_a), b = bilinear_luminance(image, s.side_b);
    const double mean = 0.5 * (a + b);
    if (!(mean > 0) || !std::isfinite(a) || !std::isfinite(b)) continue;
    difference_[k] = std::fabs(a - b) / mean;
    for (Vec2 point : {s.side_a, s.side_b})
      for (size_t texel : bilinear_taps(image.width, image.height, point).texel) seam_texels.insert(texel);
  }
  // The texels' errors in (page, texel) order over the pages in ascending order, as one set of them.
  const auto error = image.channels.find("error.Y");
  const auto coverage = image.channels.find("A");
  if (error == image.channels.end() || coverage == image.channels.end()) return;
  for (size_t texel : seam_texels) {
    if (!(coverage->second[texel] > 0)) continue;
    error_sum_ += error->second[texel];
    ++covered_;
  }
}

SeamDiscontinuity SeamDiscontinuityMeter::result() const {
  SeamDiscontinuity result;
  double sum = 0;
  for (double d : difference_)  // in sample order
    if (!std::isnan(d)) sum += d, ++result.samples;
  if (result.samples > 0) result.mean_relative_difference = sum / double(result.samples);
  if (covered_ > 0) result.mean_texel_relative_error = error_sum_ / double(covered_);
  return result;
}

SeamDiscontinuity measure_seam_discontinuity(const std::vector<formats::LightmapImage>& pages,
                                             const std::vector<SeamSample>& samples) {
  SeamDiscontinuityMeter meter(samples);
  for (size_t p = 0; p < pages.size(); ++p) meter.page(p, pages[p]);
  return meter.result();
}

}  // namespace exitance
