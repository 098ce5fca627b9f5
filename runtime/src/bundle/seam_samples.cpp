#include "exitance/runtime/bundle/seam_samples.h"

#include <algorithm>
#include <cmath>

namespace exitance {

std::vector<SeamSample> seam_samples(const std::vector<SeamEdge>& seams, float samples_per_texel) {
  std::vector<SeamSample> samples;
  for (const SeamEdge& seam : seams) {
    const Vec2 da = seam.side_a[1] - seam.side_a[0], db = seam.side_b[1] - seam.side_b[0];
    const float longer = std::max(std::hypot(da.x, da.y), std::hypot(db.x, db.y));
    const int count = std::max(1, int(std::ceil(longer * samples_per_texel)));
    for (int k = 0; k < count; ++k) {
      const float t = (float(k) + 0.5f) / float(count);
      samples.push_back({seam.page, seam.side_a[0] + da * t, seam.side_b[0] + db * t});
    }
  }
  return samples;
}

namespace {

struct AxisTaps {
  int i0, i1;
  double t;  // weight of i1
};

// As the loader's axis_taps: the coordinate minus 0.5 puts texel centres on integers, clamped.
AxisTaps axis_taps(double texel_coordinate, int texels) {
  const double x = std::clamp(texel_coordinate - 0.5, 0.0, double(texels - 1));
  const int i0 = std::min(int(std::floor(x)), texels - 1);
  return {i0, std::min(i0 + 1, texels - 1), x - i0};
}

}  // namespace

BilinearTaps bilinear_taps(int width, int height, Vec2 point) {
  const AxisTaps x = axis_taps(point.x, width), y = axis_taps(point.y, height);
  const size_t w = size_t(width);
  return {{size_t(y.i0) * w + size_t(x.i0), size_t(y.i0) * w + size_t(x.i1), size_t(y.i1) * w + size_t(x.i0),
           size_t(y.i1) * w + size_t(x.i1)},
          {(1 - x.t) * (1 - y.t), x.t * (1 - y.t), (1 - x.t) * y.t, x.t * y.t}};
}

}  // namespace exitance
