// The regular-grid guiding cache (seed 002, chapter 4; issue 11): incident radiance L_i(x, w)
// tabulated per (grid cell, normal class) over guided_direction.h's 16 x 16 equal-area hemisphere
// bins, learned online from path samples with a SARSA-style temporal-difference target, and sampled
// by the path tracer as one component of a one-sample mixture with cosine sampling.
//
// Choices (documented in docs/lighting-core.md, "Grid guiding"):
//  - Grid: cubic cells, n along the longest side of the scene bounds and as many along the others
//    as fit; n is the largest value up to `cells_on_longest_axis` (default 16) for which the
//    occupied (cell, class) records hold at least kMinTexelsPerRecord (16) texels on average, so every
//    table is learned from enough paths per pass (the thesis's 8^3 was for camera paths; lightmaps
//    at usual densities get 16, coarse test atlases fewer).
//  - Per cell, one hemisphere table per normal class (guided_direction.h), allocated only for the
//    (cell, class) pairs that lightmap texels occupy; other vertices sample cosine only.
//  - Learning target for the bin of w at x, whose ray hits y: L_e(y, -w) + albedo(y) * Lbar(y), with
//    Lbar(y) = (1/pi) * integral of the frozen table's L_i(y, .) cos over y's class hemisphere: the
//    SARSA bootstrap (thesis eq. 4.8) with its expectation over the next action memoized per record
//    at each swap (O(1) per update, like the thesis's memoized normaliser), so no state travels with
//    the path. Escaping rays learn the sky's radiance; back faces of single-sided surfaces learn 0.
//  - Double buffering: a pass's samples read the front table (frozen) and learn into the back one
//    with integer (fixed-point) atomic adds, so the sums do not depend on thread count or order;
//    swap() folds the back sums into the table (the cumulative mean of each bin's targets) and
//    rebuilds the CDFs from the bins shrunk toward their record's mean by 8 pseudo-samples.
//  - Bins have equal cosine mass (concentric_hemisphere.h), so the bin probabilities are the
//    learned L_i normalised, plus a uniform floor (kUniformFloor of the mass) so no bin has
//    probability 0, and the pdf is L_i x cos exactly up to the bins' resolution. A record with nothing learned, or
//    learned all zero, samples cosine only.
#pragma once
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "exitance/common/guide_fold.h"
#include "exitance/common/guided_direction.h"
#include "exitance/runtime/core/guide_grid_locator.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

// The fixed-point units of learned sums (common/guide_learning.h guide_fixed_point), for the grid
// and the emitter guiding caches: per unit of radiance (or value), and the cap values are clamped
// to (shaping the guide only: the estimator is unbiased whatever it learns), from the scene's
// reference radiance (GridGuidingCache::reference_radiance).
struct GuideFixedPoint {
  double units;
  float cap;
};
GuideFixedPoint guide_fixed_point_for(float reference);

struct GridGuidingConfig {
  float mix = 0.5f;               // guided component's probability at a guided vertex
  int cells_on_longest_axis = 16;
};

class GridGuidingCache {
 public:
  static constexpr uint32_t kNoRecord = GuideGridLocator::kNoRecord;
  static constexpr float kUniformFloor = 0.02f;  // common/guide_fold.h kGuideUniformFloor (GuideFold.* in guiding_math_test.cpp checks they agree)
  static constexpr double kMinTexelsPerRecord = 16;
  // Backends learn during the passes of the first samples per texel, then sample the frozen table:
  // on small scenes learning (a target per ray, atomic adds) costs as much as the ray itself, and by
  // then the table has stopped improving (bench/results/guiding.md).
  static constexpr uint32_t kLearningSamples = 64;

  // Records for the (cell, class) pairs of `gbuffer`'s texels. `scene` gives the bounds and the
  // radiance scale of the fixed-point sums (the brightest emitter or sky).
  GridGuidingCache(const LightingScene& scene, const TexelGBuffer& gbuffer, const GridGuidingConfig& config);
  // The same from what the cache reads of the scene: its bounds and reference_radiance(scene) (a
  // backend that keeps only these, the Vulkan one, builds the same cache).
  GridGuidingCache(Vec3 bounds_lo, Vec3 bounds_hi, float reference_radiance, const TexelGBuffer& gbuffer,
                   const GridGuidingConfig& config);
  // The radiance scale of the fixed-point sums: the brightest emitter or sky (luminance), else 1.
  static float reference_radiance(const LightingScene& scene);

  // The record of a surface point, kNoRecord when its (cell, class) has no texels.
  uint32_t record_of(Vec3 position, Vec3 shading_normal) const { return locator_.record_of(position, shading_normal); }
  // The strategy at a vertex of record `record` from the front table (cosine only for kNoRecord).
  GuideVertex vertex(uint32_t record) const;
  // (1/pi) * integral of the front L_i * cos over the record's class hemisphere (0 for kNoRecord).
  float expected_cosine_radiance(uint32_t record) const;
  // Adds one learning target (luminance of radiance) for `bin` of `record` to the back table.
  // Thread-safe; the sums are integers, so their result does not depend on the order of calls.
  void learn(uint32_t record, uint32_t bin, float target);
  // Adds sums learned elsewhere (the Vulkan wavefront's back table, in the same fixed-point units:
  // common/guide_learning.h guide_fixed_point with fixed_cap() and fixed_units()) to the back table
  // of `bin` of `record`, so swap() folds them exactly as it folds learn()'s.
  void import_learned(uint32_t record, uint32_t bin, uint64_t fixed_sum, uint32_t count);
  // Between passes: folds the back table into the front one, rebuilds the CDFs, clears the back
  // (common/guide_fold.h, the fold the Vulkan backend runs on the device).
  void swap();
  // A table folded elsewhere (the Vulkan backend's device fold, read back at the end of a bake):
  // per record and bin its learned radiance and weight, per record its CDF (kGuideBins + 1) and
  // front values, in record order; the back table is left as it is.
  void import_tables(const float* radiance, const float* weight, const float* cdf, const float* expected_cosine,
                     const float* guided_probability);
  // The cache's learned weights (kGuideBins per record) and the mix a learned record samples with.
  const float* weight(uint32_t record) const { return &weight_[size_t(record) * kGuideBins]; }
  float mix() const { return config_.mix; }

  uint32_t record_count() const { return uint32_t(front_.size()); }
  int cells(int axis) const { return locator_.cells(axis); }
  float cell_size() const { return locator_.cell_size(); }
  static size_t bytes_per_record();
  size_t memory_bytes() const;
  // The front table's learned radiance of a record (kGuideBins values), for plots and tests.
  const float* radiance(uint32_t record) const { return &radiance_[size_t(record) * kGuideBins]; }
  uint32_t record_of_cell(int x, int y, int z, uint normal_class) const {
    return locator_.record_of_cell(x, y, z, normal_class);
  }

  // The locator and the front table as a device copies them (runtime/src/vulkan/guide_buffer.cpp).
  Vec3 grid_origin() const { return locator_.origin(); }
  const GuideGridLocator& locator() const { return locator_; }
  // Per (cell, class), cell (z * cells(1) + y) * cells(0) + x: its record or kNoRecord.
  const std::vector<uint32_t>& record_index() const { return locator_.record_index(); }
  double fixed_units() const { return fixed_scale_; }  // fixed-point units per unit of radiance
  float fixed_cap() const { return target_cap_; }      // targets are clamped here before conversion

 private:
  // What a vertex reads (small and together: the hot data of every path vertex).
  struct Front {
    float guided_probability = 0;  // config mix, or 0 while nothing is learned
    float expected_cosine = 0;     // Lbar
    uint32_t normal_class = 0;
  };
  // A bin of the back table: sum and count on one cache line.
  struct BinAccumulator {
    std::atomic<uint64_t> sum{0};   // fixed-point
    std::atomic<uint32_t> count{0};
  };
  void rebuild(uint32_t record);

  GridGuidingConfig config_;
  GuideGridLocator locator_;
  double fixed_scale_ = 1;  // fixed-point units per unit of radiance
  float target_cap_ = 0;    // targets are clamped here (guiding only: no estimator bias)
  std::vector<Front> front_;
  std::vector<float> cdf_;       // kGuideBins + 1 per record
  std::vector<float> radiance_;  // kGuideBins per record: learned L_i
  std::vector<float> weight_;    // kGuideBins per record: effective sample count behind each value
  std::unique_ptr<BinAccumulator[]> back_;  // kGuideBins per record
};

}  // namespace exitance
