// The guiding grid: see guide_grid_locator.h.
#include "exitance/runtime/core/guide_grid_locator.h"

#include <algorithm>
#include <cmath>

namespace exitance {

GuideGridLocator::GuideGridLocator(Vec3 bounds_lo, Vec3 bounds_hi, const TexelGBuffer& gbuffer, int cells_on_longest_axis,
                                   double min_texels_per_record)
    : lo_(bounds_lo) {
  const Vec3 extent = bounds_hi - bounds_lo;
  const float longest = std::max({extent.x, extent.y, extent.z});
  // The finest grid whose records average min_texels_per_record texels.
  for (int n = std::max(1, cells_on_longest_axis);; --n) {
    cell_size_ = longest > 0 && std::isfinite(longest) ? longest / float(n) : 1.0f;
    for (int a = 0; a < 3; ++a) dims_[a] = std::clamp(int(std::ceil(extent[a] / cell_size_)), 1, n);
    const size_t cells = size_t(dims_[0]) * size_t(dims_[1]) * size_t(dims_[2]);
    record_index_.assign(cells * kGuideNormalClasses, kNoRecord);
    record_class_.clear();
    for (const LiveTexel& t : gbuffer.texels) {
      const uint normal_class = guide_normal_class(t.shading_normal);
      const size_t key = size_t(cell_index(t.position)) * kGuideNormalClasses + normal_class;
      if (record_index_[key] != kNoRecord) continue;
      record_index_[key] = uint32_t(record_class_.size());
      record_class_.push_back(normal_class);
    }
    if (n == 1 || double(gbuffer.texels.size()) >= min_texels_per_record * double(record_class_.size())) break;
  }
}

uint32_t GuideGridLocator::cell_index(Vec3 p) const {
  int c[3];
  for (int a = 0; a < 3; ++a) {
    const float f = (p[a] - lo_[a]) / cell_size_;
    c[a] = f >= 0 ? std::min(int(std::min(f, 1e9f)), dims_[a] - 1) : 0;  // NaN and below: cell 0
  }
  return uint32_t((c[2] * dims_[1] + c[1]) * dims_[0] + c[0]);
}

uint32_t GuideGridLocator::record_of_cell(int x, int y, int z, uint normal_class) const {
  if (x < 0 || y < 0 || z < 0 || x >= dims_[0] || y >= dims_[1] || z >= dims_[2]) return kNoRecord;
  return record_index_[size_t((z * dims_[1] + y) * dims_[0] + x) * kGuideNormalClasses + normal_class];
}

}  // namespace exitance
