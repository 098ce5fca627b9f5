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

// Bilinear weights of the four texels around (u, v), shared by the RGB and the one-channel lookups.
struct BilinearTaps {
  size_t top_left, top_right, bottom_left, bottom_right;
  float tx, ty;

  float apply(const float* d) const {
    const float top = d[top_left] * (1 - tx) + d[top_right] * tx;
    const float bottom = d[bottom_left] * (1 - tx) + d[bottom_right] * tx;
    return top * (1 - ty) + bottom * ty;
  }
};

BilinearTaps bilinear_taps(const formats::LightmapImage& page, float u, float v) {
  const AxisTaps x = axis_taps(u, page.width), y = axis_taps(v, page.height);
  const size_t w = size_t(page.width);
  return {size_t(y.i0) * w + x.i0, size_t(y.i0) * w + x.i1, size_t(y.i1) * w + x.i0, size_t(y.i1) * w + x.i1, x.t, y.t};
}

}  // namespace

Rgb bilinear_page_rgb(const formats::LightmapImage& page, float u, float v) {
  const BilinearTaps taps = bilinear_taps(page, u, v);
  return {taps.apply(page.channels.at("R").data()), taps.apply(page.channels.at("G").data()),
          taps.apply(page.channels.at("B").data())};
}

float bilinear_page_channel(const formats::LightmapImage& page, const std::string& channel, float u, float v) {
  return bilinear_taps(page, u, v).apply(page.channels.at(channel).data());
}

}  // namespace exitance::loader
