#include "lightmap_lookup.h"

#include <algorithm>
#include <cmath>

namespace exitance::loader {
namespace {

struct AxisTaps {
  int i0, i1;
  float t;  // weight of i1
};

// Texel coordinate of the lookup minus 0.5 puts texel centres on integers; clamping the
// coordinate to [0, n-1] first gives clamp-to-edge and keeps the integer conversion in range.
AxisTaps axis_taps(float page_coordinate, int texels) {
  const double x = std::clamp(double(page_coordinate) * texels - 0.5, 0.0, double(texels - 1));
  const int i0 = std::min(int(std::floor(x)), texels - 1);
  const int i1 = std::min(i0 + 1, texels - 1);
  return {i0, i1, float(x - i0)};
}

}  // namespace

Rgb bilinear_page_rgb(const formats::LightmapImage& page, float u, float v) {
  const AxisTaps x = axis_taps(u, page.width), y = axis_taps(v, page.height);
  const size_t w = size_t(page.width);
  const float* channels[3] = {page.channels.at("R").data(), page.channels.at("G").data(), page.channels.at("B").data()};
  Rgb out{};
  for (int c = 0; c < 3; ++c) {
    const float* d = channels[c];
    const float top = d[size_t(y.i0) * w + x.i0] * (1 - x.t) + d[size_t(y.i0) * w + x.i1] * x.t;
    const float bottom = d[size_t(y.i1) * w + x.i0] * (1 - x.t) + d[size_t(y.i1) * w + x.i1] * x.t;
    out[c] = top * (1 - y.t) + bottom * y.t;
  }
  return out;
}

}  // namespace exitance::loader
