// The regular grid that places a path vertex in a guiding record (issue 11): cubic cells over the
// scene bounds, n along the longest side and as many along the others as fit, one record per
// (cell, normal class) that lightmap texels occupy. n is the largest value up to
// `cells_on_longest_axis` for which the records hold at least `min_texels_per_record` texels on
// average, so every record learns from enough paths per pass. Used by the grid guiding cache
// (directions) and the emitter guiding cache (next-event patches).
#pragma once
#include <cstdint>
#include <vector>

#include "exitance/common/guided_direction.h"
#include "exitance/runtime/texel_gbuffer.h"
#include "exitance/runtime/vec_math.h"

namespace exitance {

class GuideGridLocator {
 public:
  static constexpr uint32_t kNoRecord = 0xFFFFFFFFu;

  GuideGridLocator(Vec3 bounds_lo, Vec3 bounds_hi, const TexelGBuffer& gbuffer, int cells_on_longest_axis,
                   double min_texels_per_record);

  // The record of a surface point, kNoRecord when its (cell, class) has no texels.
  uint32_t record_of(Vec3 position, Vec3 shading_normal) const {
    return record_index_[size_t(cell_index(position)) * kGuideNormalClasses + guide_normal_class(shading_normal)];
  }
  uint32_t record_of_cell(int x, int y, int z, uint normal_class) const;
  // Cell (z * cells(1) + y) * cells(0) + x of a point: NaN and below the origin go to cell 0.
  uint32_t cell_index(Vec3 position) const;

  uint32_t record_count() const { return uint32_t(record_class_.size()); }
  uint normal_class(uint32_t record) const { return record_class_[record]; }
  int cells(int axis) const { return dims_[axis]; }
  float cell_size() const { return cell_size_; }
  Vec3 origin() const { return lo_; }
  // Per (cell, class): its record or kNoRecord.
  const std::vector<uint32_t>& record_index() const { return record_index_; }
  size_t memory_bytes() const { return (record_index_.size() + record_class_.size()) * sizeof(uint32_t); }

 private:
  Vec3 lo_;
  float cell_size_ = 1;
  int dims_[3] = {1, 1, 1};
  std::vector<uint32_t> record_index_;
  std::vector<uint32_t> record_class_;
};

}  // namespace exitance
