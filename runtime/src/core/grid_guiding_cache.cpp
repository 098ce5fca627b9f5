// The regular-grid guiding cache: see grid_guiding_cache.h for the choices.
#include "exitance/runtime/core/grid_guiding_cache.h"

#include <algorithm>
#include <cmath>

#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance/runtime/core/scene_access.h"
#include "exitance/common/guide_learning.h"  // after scene_access.h: path.h reads its accessors

namespace exitance {
namespace {

// Old sample counts are kept at every swap (a cumulative mean, as the thesis accumulates): passes
// are small (a few spp), and halving per swap left ~4 samples behind a bin (plots in
// bench/results/guiding.md), whose noise the sampler then followed.
constexpr float kCountDecay = 1.0f;
// Each bin's value is shrunk toward its record's mean by this many pseudo-samples, so a bin seen a
// few times (one lucky emitter hit) does not draw the sampler.
constexpr double kPriorSamples = 8;

}  // namespace

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
            weight_[i] *= kCountDecay;
            if (count == 0) continue;
            const uint64_t sum = a.sum.load(std::memory_order_relaxed);
            a.count.store(0, std::memory_order_relaxed);
            a.sum.store(0, std::memory_order_relaxed);
            const float mean = float(double(sum) / fixed_scale_ / double(count));
            const float w = weight_[i] + float(count);
            radiance_[i] += (mean - radiance_[i]) * (float(count) / w);
            weight_[i] = w;
            changed = true;
          }
          if (changed) rebuild(uint32_t(r));
        }
      },
      64);
}

void GridGuidingCache::rebuild(uint32_t record) {
  const float* learned_radiance = &radiance_[size_t(record) * kGuideBins];
  const float* weight = &weight_[size_t(record) * kGuideBins];
  float* cdf = &cdf_[size_t(record) * (kGuideBins + 1)];
  double weighted = 0, weights = 0;
  for (uint b = 0; b < kGuideBins; ++b) {
    weighted += double(weight[b]) * learned_radiance[b];
    weights += weight[b];
  }
  const double prior = weights > 0 ? weighted / weights : 0.0;
  double radiance[kGuideBins];
  double total = 0;
  for (uint b = 0; b < kGuideBins; ++b) {
    radiance[b] = (double(weight[b]) * learned_radiance[b] + kPriorSamples * prior) / (double(weight[b]) + kPriorSamples);
    total += radiance[b];
  }
  const bool learned = total > 0 && std::isfinite(total);
  // (1/pi) * integral of L cos = (1/pi) * sum of L_b * (pi / bins): every bin has cosine mass pi / bins.
  front_[record].expected_cosine = learned ? float(total / kGuideBins) : 0.0f;
  front_[record].guided_probability = learned ? config_.mix : 0.0f;
  double run = 0;
  cdf[0] = 0;
  for (uint b = 0; b < kGuideBins; ++b) {
    const double share = learned ? radiance[b] / total : 0.0;
    run += (1.0 - kUniformFloor) * share + kUniformFloor / kGuideBins;
    cdf[b + 1] = float(std::min(run, 1.0));
  }
  cdf[kGuideBins] = 1.0f;
}

size_t GridGuidingCache::bytes_per_record() {
  return sizeof(Front) + sizeof(float) * (kGuideBins + 1) + 2 * sizeof(float) * kGuideBins +
         sizeof(BinAccumulator) * kGuideBins;
}

size_t GridGuidingCache::memory_bytes() const {
  return bytes_per_record() * front_.size() + locator_.memory_bytes();
}

}  // namespace exitance
