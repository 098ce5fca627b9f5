// The regular-grid guiding cache: see grid_guiding_cache.h for the choices.
#include "exitance/runtime/core/grid_guiding_cache.h"

#include <algorithm>
#include <cmath>

#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance/runtime/core/scene_access.h"
#include "exitance/common/guide_learning.h"  // after scene_access.h: path.h reads its accessors
#include "exitance/common/guide_fold.h"

namespace exitance {

GuideFixedPoint guide_fixed_point_for(float reference) {
  // Fixed-point sums: 2^24 units per reference radiance, values capped at 2^16 references, so one
  // sum overflows its 64 bits only after 2^24 capped values in one pass. A scene without emission
  // or sky has reference 1 (it learns 0).
  if (!(reference > 0) || !std::isfinite(reference)) reference = 1.0f;
  return {16777216.0 / double(reference), reference * 65536.0f};
}

float GridGuidingCache::reference_radiance(const LightingScene& scene) {
  float reference = luminance(scene.sky);
  for (const GpuMaterial& m : scene.materials)
    reference = std::max(reference, luminance(Vec3(m.emission.x, m.emission.y, m.emission.z)));
  return reference;
}

GridGuidingCache::GridGuidingCache(const LightingScene& scene, const TexelGBuffer& gbuffer,
                                   const GridGuidingConfig& config)
    : GridGuidingCache(scene.bounds_lo, scene.bounds_hi, reference_radiance(scene), gbuffer, config) {}

GridGuidingCache::GridGuidingCache(Vec3 bounds_lo, Vec3 bounds_hi, float reference, const TexelGBuffer& gbuffer,
                                   const GridGuidingConfig& config)
    : config_(config), locator_(bounds_lo, bounds_hi, gbuffer, config.cells_on_longest_axis, kMinTexelsPerRecord) {
  config_.mix = std::clamp(config_.mix, 0.0f, 1.0f);
  front_.resize(locator_.record_count());
  for (uint32_t r = 0; r < front_.size(); ++r) front_[r].normal_class = locator_.normal_class(r);

  const GuideFixedPoint fixed = guide_fixed_point_for(reference);
  fixed_scale_ = fixed.units;
  target_cap_ = fixed.cap;

  const size_t records = front_.size();
  cdf_.assign(records * (kGuideBins + 1), 0.0f);
  radiance_.assign(records * kGuideBins, 0.0f);
  weight_.assign(records * kGuideBins, 0.0f);
  back_.reset(new BinAccumulator[records * kGuideBins]);
  for (uint32_t r = 0; r < records; ++r) rebuild(r);
}

GuideVertex GridGuidingCache::vertex(uint32_t record) const {
  GuideVertex g;
  g.guided_probability = 0;
  g.normal_class = 0;
  g.cdf = nullptr;
  g.uniform_probability = 0;
  if (record == kNoRecord) return g;
  const Front& f = front_[record];
  g.guided_probability = f.guided_probability;
  g.normal_class = f.normal_class;
  g.cdf = &cdf_[size_t(record) * (kGuideBins + 1)];
  return g;
}

float GridGuidingCache::expected_cosine_radiance(uint32_t record) const {
  return record == kNoRecord ? 0.0f : front_[record].expected_cosine;
}

void GridGuidingCache::learn(uint32_t record, uint32_t bin, float target) {
  if (record == kNoRecord || bin >= kGuideBins || !(target >= 0)) return;  // NaN never enters
  BinAccumulator& a = back_[size_t(record) * kGuideBins + bin];
  a.sum.fetch_add(guide_fixed_point(target, target_cap_, fixed_scale_), std::memory_order_relaxed);
  a.count.fetch_add(1, std::memory_order_relaxed);
}

void GridGuidingCache::import_learned(uint32_t record, uint32_t bin, uint64_t fixed_sum, uint32_t count) {
  if (record >= front_.size() || bin >= kGuideBins || count == 0) return;
  BinAccumulator& a = back_[size_t(record) * kGuideBins + bin];
  a.sum.fetch_add(fixed_sum, std::memory_order_relaxed);
  a.count.fetch_add(count, std::memory_order_relaxed);
}

void GridGuidingCache::swap() {
  // Records are independent (each folds and rebuilds only its own bins): on all cores.
  for_each_chunk(
      front_.size(),
      [&](size_t first, size_t end) {
        for (size_t r = first; r < end; ++r) {
          bool changed = false;
          for (uint b = 0; b < kGuideBins; ++b) {
            const size_t i = r * kGuideBins + b;
            BinAccumulator& a = back_[i];
            const uint32_t count = a.count.load(std::memory_order_relaxed);
            const uint64_t sum = a.sum.load(std::memory_order_relaxed);
            a.count.store(0, std::memory_order_relaxed);
            a.sum.store(0, std::memory_order_relaxed);
            changed |= guide_fold_bin(radiance_[i], weight_[i], sum, count, fixed_scale_);
          }
          if (changed) rebuild(uint32_t(r));
        }
      },
      64);
}

void GridGuidingCache::rebuild(uint32_t record) {
  const size_t at = size_t(record) * kGuideBins;
  const GuideFoldFront front =
      guide_fold_rebuild(GuideFoldRecord{&radiance_[at], &weight_[at], &cdf_[size_t(record) * (kGuideBins + 1)]}, config_.mix);
  front_[record].expected_cosine = front.expected_cosine;
  front_[record].guided_probability = front.guided_probability;
}

void GridGuidingCache::import_tables(const float* radiance, const float* weight, const float* cdf, const float* expected_cosine,
                                     const float* guided_probability) {
  std::copy(radiance, radiance + radiance_.size(), radiance_.begin());
  std::copy(weight, weight + weight_.size(), weight_.begin());
  std::copy(cdf, cdf + cdf_.size(), cdf_.begin());
  for (size_t r = 0; r < front_.size(); ++r) {
    front_[r].expected_cosine = expected_cosine[r];
    front_[r].guided_probability = guided_probability[r];
  }
}

size_t GridGuidingCache::bytes_per_record() {
  return sizeof(Front) + sizeof(float) * (kGuideBins + 1) + 2 * sizeof(float) * kGuideBins +
         sizeof(BinAccumulator) * kGuideBins;
}

size_t GridGuidingCache::memory_bytes() const {
  return bytes_per_record() * front_.size() + locator_.memory_bytes();
}

}  // namespace exitance
