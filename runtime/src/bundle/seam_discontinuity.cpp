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

SeamDiscontinuity measure_seam_discontinuity(const std::vector<formats::LightmapImage>& pages,
                                             const std::vector<SeamSample>& samples) {
  SeamDiscontinuity result;
  double sum = 0;
  std::set<std::pair<int, size_t>> seam_texels;
  for (const SeamSample& s : samples) {
    if (s.page < 0 || size_t(s.page) >= pages.size() || !pages[size_t(s.page)].channels.count("R")) continue;
    const formats::LightmapImage& page = pages[size_t(s.page)];
    const double a = bilinear_luminance(page, s.side_a), b = bilinear_luminance(page, s.side_b);
    const double mean = 0.5 * (a + b);
    if (!(mean > 0) || !std::isfinite(a) || !std::isfinite(b)) continue;
    sum += std::fabs(a - b) / mean;
    ++result.samples;
    for (Vec2 point : {s.side_a, s.side_b})
      for (size_t texel : bilinear_taps(page.width, page.height, point).texel) seam_texels.insert({s.page, texel});
  }
  if (result.samples > 0) result.mean_relative_difference = sum / double(result.samples);
  double error_sum = 0;
  size_t covered = 0;
  for (const auto& [page_index, texel] : seam_texels) {
    const formats::LightmapImage& page = pages[size_t(page_index)];
    const auto error = page.channels.find("error.Y");
    const auto coverage = page.channels.find("A");
    if (error == page.channels.end() || coverage == page.channels.end() || !(coverage->second[texel] > 0)) continue;
    error_sum += error->second[texel];
    ++covered;
  }
  if (covered > 0) result.mean_texel_relative_error = error_sum / double(covered);
  return result;
}

}  // namespace exitance
