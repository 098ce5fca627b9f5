// Emitter guiding: see emitter_guiding_cache.h for the choices.
#include "exitance/runtime/core/emitter_guiding_cache.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "exitance/formats/huge_pages.h"
#include "exitance/runtime/core/grid_guiding_cache.h"
#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance/runtime/core/scene_access.h"
#include "exitance/common/guide_learning.h"  // after scene_access.h: path.h reads its accessors

namespace exitance {
namespace {

// Back sum and count (one 16-byte accumulator), cumulative samples, cumulative sum, CDF entry.
constexpr size_t kBytesPerRecordPatch = 16 + sizeof(uint32_t) + sizeof(double) + sizeof(float);

}  // namespace

EmitterPatches build_emitter_patches(const std::vector<double>& cdf, uint32_t target, uint32_t cluster_target) {
  EmitterPatches p;
  const size_t emitters = cdf.size() > 0 ? cdf.size() - 1 : 0;
  p.emitter_patch.resize(emitters);
  const double t = std::max<uint32_t>(target, 1);
  for (size_t e = 0; e < emitters;) {
    const double share = cdf[e + 1] - cdf[e];
    const uint32_t first = p.count();
    if (share * t >= 1) {  // its own 4^L sub-triangles, 4^L <= share * target
      uint32_t level = 0;
      while (level < kEmitterPatchMaxLevel && double(1u << (2 * (level + 1))) <= share * t) ++level;
      p.emitter_patch[e] = first << 3 | level;
      const uint32_t subs = 1u << (2 * level);
      for (uint32_t s = 0; s < subs; ++s) {
        p.patch_emitters.push_back(uint32_t(e));
        p.patch_emitters.push_back(uint32_t(e + 1));
        p.default_probability.push_back(float(share / subs));
      }
      ++e;
      continue;
    }
    // A run of dimmer emitters sharing at most 1 / target of the power.
    const size_t begin = e;
    double sum = 0;
    while (e < emitters) {
      const double s = cdf[e + 1] - cdf[e];
      if (e > begin && (s * t >= 1 || (sum + s) * t > 1)) break;
      sum += s;
      p.emitter_patch[e] = first << 3;
      ++e;
    }
    p.patch_emitters.push_back(uint32_t(begin));
    p.patch_emitters.push_back(uint32_t(e));
    p.default_probability.push_back(float(sum));
  }
  // Clusters: runs of units (an emitter's sub-triangles, or one shared patch) up to 1 / cluster_target.
  const double ct = std::max<uint32_t>(cluster_target, 1);
  double cluster_share = 0;
  for (uint32_t k = 0; k < p.count();) {
    const uint32_t first_emitter = p.patch_emitters[2 * k];
    const uint32_t unit = 1u << (2 * (p.emitter_patch[first_emitter] & 7));  // 4^level patches
    double unit_share = 0;
    for (uint32_t j = k; j < k + unit; ++j) unit_share += p.default_probability[j];
    if (p.cluster_first.empty() || (cluster_share + unit_share) * ct > 1) {
      p.cluster_first.push_back(k);
      cluster_share = 0;
    }
    cluster_share += unit_share;
    k += unit;
  }
  p.cluster_first.push_back(p.count());
  return p;
}

EmitterGuidingCache::EmitterGuidingCache(const LightingScene& scene, const TexelGBuffer& gbuffer,
                                         const EmitterGuidingConfig& config)
    : config_(config),
      locator_(scene.bounds_lo, scene.bounds_hi, gbuffer, config.cells_on_longest_axis,
               GridGuidingCache::kMinTexelsPerRecord) {
  config_.mix = std::clamp(config_.mix, 0.0f, 1.0f);
  const size_t records = locator_.record_count();
  // Patches at most twice the target, so the budget bounds the target.
  uint32_t target = std::max<uint32_t>(config_.patch_target, 1);
  if (records > 0)
    target = uint32_t(std::clamp<size_t>(kMemoryBudget / (2 * kBytesPerRecordPatch * records), 1, target));
  if (scene.emitter_count() > 0) patches_ = build_emitter_patches(scene.emitter_cdf, target, config_.cluster_target);
  triangle_emitter_.assign(scene.triangles.size(), kEmitterPatchNone);
  for (uint32_t e = 0; e < scene.emitter_count(); ++e) triangle_emitter_[scene.emitter_triangles[e]] = e;

  const GuideFixedPoint fixed = guide_fixed_point_for(GridGuidingCache::reference_radiance(scene));
  fixed_scale_ = fixed.units;
  value_cap_ = fixed.cap;

  const size_t patches = patch_count();
  guided_probability_.assign(records, 0.0f);
  // Tens of MB at a million texels: zeros first touched in huge pages where the kernel allows.
  formats::resize_in_huge_pages(cdf_, records * (patches + 1));
  if (scene.punctual_count() >= 2 && scene.punctual_count() <= kMostGuidedPunctualLights) {
    punctual_count_ = scene.punctual_count();
    for (uint32_t i = 0; i < punctual_count_; ++i)
      punctual_default_.push_back(float(scene.punctual_cdf[i + 1] - scene.punctual_cdf[i]));
    punctual_guided_probability_.assign(records, 0.0f);
    punctual_cdf_.assign(records * (punctual_count_ + 1), 0.0f);
  }
  if (config_.learns_on_host) {  // the learned sums and the back tables (a device fold keeps its own)
    allocate_learned();
    back_.reset(new Accumulator[records * patches]);
    if (punctual_count_ > 0) {
      punctual_back_.reset(new std::atomic<uint64_t>[records * punctual_count_]);
      for (size_t i = 0; i < records * punctual_count_; ++i) punctual_back_[i].store(0, std::memory_order_relaxed);
    }
  }
  if (records == 0) return;
  // Nothing learned yet: every record's tables are the same default ones, built once for record 0
  // from zero sums and copied to the others on all cores.
  const std::vector<double> zeros(std::max<size_t>(std::max<size_t>(patches, punctual_count_), 1), 0.0);
  const std::vector<uint32_t> zero_samples(std::max<size_t>(patches, 1), 0u);
  EmitterFoldRecord first = fold_record(0);
  first.learned = zeros.data(), first.samples = zero_samples.data(), first.punctual_learned = zeros.data();
  rebuild(0, first);
  for_each_chunk(records, [&](size_t begin, size_t end) {
    for (size_t r = std::max<size_t>(begin, 1); r < end; ++r) {
      std::copy(cdf_.begin(), cdf_.begin() + std::ptrdiff_t(patches + 1), cdf_.begin() + std::ptrdiff_t(r * (patches + 1)));
      guided_probability_[r] = guided_probability_[0];
      if (punctual_count_ == 0) continue;
      std::copy(punctual_cdf_.begin(), punctual_cdf_.begin() + std::ptrdiff_t(punctual_count_ + 1),
                punctual_cdf_.begin() + std::ptrdiff_t(r * (punctual_count_ + 1)));
      punctual_guided_probability_[r] = punctual_guided_probability_[0];
    }
  }, 64);
}

void EmitterGuidingCache::allocate_learned() {
  const size_t records = record_count();
  formats::resize_in_huge_pages(learned_, records * patch_count());
  formats::resize_in_huge_pages(samples_, records * patch_count());
  punctual_learned_.assign(records * punctual_count_, 0.0);
}

std::unique_ptr<EmitterGuidingCache> EmitterGuidingCache::for_bake(const LightingScene& scene,
                                                                  const TexelGBuffer& gbuffer,
                                                                  const IntegratorSettings& settings,
                                                                  bool learns_on_host) {
  if (!settings.emitter_guiding || !guides(scene)) return nullptr;
  EmitterGuidingConfig config;
  config.learns_on_host = learns_on_host;
  config.mix = settings.emitter_guiding_mix;
  config.cells_on_longest_axis = settings.guiding_grid_cells;
  config.patch_target = settings.emitter_guiding_patches;
  return std::make_unique<EmitterGuidingCache>(scene, gbuffer, config);
}

bool EmitterGuidingCache::guides(const LightingScene& scene) { return scene.emitter_count() > 0 || scene.punctual_count() >= 2; }

uint32_t EmitterGuidingCache::record_of(Vec3 position, Vec3 shading_normal) const {
  return patch_count() > 0 || punctual_count_ > 0 ? locator_.record_of(position, shading_normal) : kNoRecord;
}

EmitterGuide EmitterGuidingCache::vertex(uint32_t record) const {
  EmitterGuide g = emitter_guide_none();
  if (record == kNoRecord) return g;
  if (patch_count() > 0) {
    g.guided_probability = guided_probability_[record];
    g.cdf = &cdf_[size_t(record) * (patch_count() + 1)];
    g.patch_count = patch_count();
    g.emitter_patch = patches_.emitter_patch.data();
    g.patch_emitters = patches_.patch_emitters.data();
    g.triangle_emitter = triangle_emitter_.data();
  }
  if (punctual_count_ > 0) {
    g.punctual_guided_probability = punctual_guided_probability_[record];
    g.punctual_cdf = &punctual_cdf_[size_t(record) * (punctual_count_ + 1)];
    g.punctual_count = punctual_count_;
  }
  return g;
}

EmitterGuidingCache::Site EmitterGuidingCache::vertex_site(EmitterGuidingCache* cache, Vec3 position,
                                                           Vec3 shading_normal, Learning learning) {
  Site s;
  if (!cache) return s;
  s.record = cache->record_of(position, shading_normal);
  const EmitterGuide guide = cache->vertex(s.record);
  const bool sampling_learned = emitter_guide_samples_learned(guide);
  s.learns = emitter_vertex_learns(uint(learning), s.record != kNoRecord, sampling_learned);
  if (s.learns || sampling_learned) s.guide = guide;
  return s;
}

void EmitterGuidingCache::learn_arrived(const Site& site, uint32_t patch, float value, bool area_arrived,
                                        uint32_t punctual_light, float punctual_value, bool punctual_arrived) {
  if (!site.learns) return;
  if (area_arrived && patch != kEmitterPatchNone) learn(site.record, patch, value);
  if (punctual_arrived && punctual_light != kEmitterPatchNone) learn_punctual(site.record, punctual_light, punctual_value);
}

void EmitterGuidingCache::learn(uint32_t record, uint32_t patch, float value) {
  if (record == kNoRecord || patch >= patch_count() || !(value > 0)) return;  // NaN never enters
  Accumulator& a = back_[size_t(record) * patch_count() + patch];
  a.sum.fetch_add(guide_fixed_point(value, value_cap_, fixed_scale_), std::memory_order_relaxed);
  a.count.fetch_add(1, std::memory_order_relaxed);
}

void EmitterGuidingCache::learn_punctual(uint32_t record, uint32_t light, float value) {
  if (record == kNoRecord || light >= punctual_count_ || !(value > 0)) return;
  punctual_back_[size_t(record) * punctual_count_ + light].fetch_add(guide_fixed_point(value, value_cap_, fixed_scale_),
                                                                     std::memory_order_relaxed);
}

void EmitterGuidingCache::import_learned(uint32_t record, uint32_t patch, uint64_t fixed_sum, uint32_t count) {
  if (!config_.learns_on_host) throw std::logic_error("EmitterGuidingCache::import_learned: a cache made for a device fold");
  if (record >= record_count() || patch >= patch_count() || count == 0) return;
  Accumulator& a = back_[size_t(record) * patch_count() + patch];
  a.sum.fetch_add(fixed_sum, std::memory_order_relaxed);
  a.count.fetch_add(count, std::memory_order_relaxed);
}

void EmitterGuidingCache::import_learned_punctual(uint32_t record, uint32_t light, uint64_t fixed_sum) {
  if (!config_.learns_on_host) throw std::logic_error("EmitterGuidingCache::import_learned_punctual: a cache made for a device fold");
  if (record >= record_count() || light >= punctual_count_ || fixed_sum == 0) return;
  punctual_back_[size_t(record) * punctual_count_ + light].fetch_add(fixed_sum, std::memory_order_relaxed);
}

void EmitterGuidingCache::swap() {
  if (!config_.learns_on_host) throw std::logic_error("EmitterGuidingCache::swap: a cache made for a device fold");
  // Records are independent (each folds and rebuilds only its own rows): on all cores.
  const size_t patches = patch_count();
  for_each_chunk(
      record_count(),
      [&](size_t first, size_t end) {
        for (size_t r = first; r < end; ++r) {
          bool changed = false;
          for (size_t k = 0; k < patches; ++k) {
            Accumulator& a = back_[r * patches + k];
            const uint32_t count = a.count.load(std::memory_order_relaxed);
            if (count == 0) continue;
            const uint64_t units = a.sum.load(std::memory_order_relaxed);
            a.sum.store(0, std::memory_order_relaxed);
            a.count.store(0, std::memory_order_relaxed);
            emitter_fold_add(learned_[r * patches + k], units, fixed_scale_);
            samples_[r * patches + k] += count;
            changed = true;
          }
          for (size_t i = 0; i < punctual_count_; ++i) {
            std::atomic<uint64_t>& sum = punctual_back_[r * punctual_count_ + i];
            const uint64_t units = sum.load(std::memory_order_relaxed);
            if (units == 0) continue;
            sum.store(0, std::memory_order_relaxed);
            emitter_fold_add(punctual_learned_[r * punctual_count_ + i], units, fixed_scale_);
            changed = true;
          }
          if (changed) rebuild(uint32_t(r), fold_record(uint32_t(r)));
        }
      },
      16);
}

void EmitterGuidingCache::import_folded(uint32_t record, const double* learned, const uint32_t* samples, const float* cdf,
                                        float guided_probability, const double* punctual_learned,
                                        const float* punctual_cdf, float punctual_guided_probability) {
  if (record >= record_count()) return;
  if (!config_.learns_on_host && learned_.size() + punctual_learned_.size() == 0) allocate_learned();
  const size_t patches = patch_count();
  if (patches > 0) {
    std::copy(learned, learned + patches, &learned_[size_t(record) * patches]);
    std::copy(samples, samples + patches, &samples_[size_t(record) * patches]);
    std::copy(cdf, cdf + patches + 1, &cdf_[size_t(record) * (patches + 1)]);
    guided_probability_[record] = guided_probability;
  }
  if (punctual_count_ > 0) {
    std::copy(punctual_learned, punctual_learned + punctual_count_, &punctual_learned_[size_t(record) * punctual_count_]);
    std::copy(punctual_cdf, punctual_cdf + punctual_count_ + 1, &punctual_cdf_[size_t(record) * (punctual_count_ + 1)]);
    punctual_guided_probability_[record] = punctual_guided_probability;
  }
}

void EmitterGuidingCache::end_pass(uint32_t samples) {
  if (!active_) return;
  swap();
  if (samples >= kEveryLearningSamples && !samples_anywhere()) active_ = false;
}

void EmitterGuidingCache::report(LightmapEstimate::EmitterGuidingReport& out) const {
  out.records = record_count();
  out.records_sampling_learned = active_ ? records_sampling_learned() : 0;
  out.patches = patch_count();
  out.punctual_lights = punctual_count();
  out.memory_bytes = memory_bytes();
  out.dropped = !active_;
}

EmitterFoldRecord EmitterGuidingCache::fold_record(uint32_t record) {
  EmitterFoldRecord r{};
  const size_t patches = patch_count();
  if (patches > 0) {
    // data() + offset: on a cache made for a device fold these are empty until an import.
    r.learned = learned_.data() + size_t(record) * patches;
    r.samples = samples_.data() + size_t(record) * patches;
    r.default_probability = patches_.default_probability.data();
    r.cluster_first = patches_.cluster_first.data();
    r.cdf = &cdf_[size_t(record) * (patches + 1)];
  }
  if (punctual_count_ > 0) {
    r.punctual_learned = punctual_learned_.data() + size_t(record) * punctual_count_;
    r.punctual_default = punctual_default_.data();
    r.punctual_cdf = &punctual_cdf_[size_t(record) * (punctual_count_ + 1)];
  }
  return r;
}

void EmitterGuidingCache::rebuild(uint32_t record, const EmitterFoldRecord& r) {
  // common/emitter_guide_fold.h: the device's fold (fold_emitter_guide.comp) runs the same code.
  if (punctual_count_ > 0) punctual_guided_probability_[record] = emitter_fold_rebuild_punctual(r, punctual_count_, config_.mix);
  if (patch_count() > 0)
    guided_probability_[record] = emitter_fold_rebuild_patches(r, patch_count(), patches_.cluster_count(), config_.mix);
}

uint32_t EmitterGuidingCache::records_sampling_learned() const {
  uint32_t records = 0;
  for (uint32_t r = 0; r < record_count(); ++r)
    records += guided_probability_[r] > 0 || (punctual_count_ > 0 && punctual_guided_probability_[r] > 0);
  return records;
}

float EmitterGuidingCache::probability(uint32_t record, uint32_t patch) const {
  if (record >= record_count() || patch >= patch_count() || !(guided_probability_[record] > 0)) return 0.0f;
  const float* cdf = &cdf_[size_t(record) * (patch_count() + 1)];
  return std::max(cdf[patch + 1] - cdf[patch], 0.0f);
}

float EmitterGuidingCache::punctual_probability(uint32_t record, uint32_t light) const {
  if (record >= record_count() || light >= punctual_count_ || !(punctual_guided_probability_[record] > 0)) return 0.0f;
  const float* cdf = &punctual_cdf_[size_t(record) * (punctual_count_ + 1)];
  return std::max(cdf[light + 1] - cdf[light], 0.0f);
}

size_t EmitterGuidingCache::memory_bytes() const {
  return size_t(record_count()) * (patch_count() * kBytesPerRecordPatch + sizeof(float) * 2) + locator_.memory_bytes() +
         (patches_.emitter_patch.size() + patches_.patch_emitters.size() + triangle_emitter_.size()) * sizeof(uint32_t) +
         patches_.default_probability.size() * sizeof(float) + patches_.cluster_first.size() * sizeof(uint32_t) +
         size_t(record_count()) * punctual_count_ * (sizeof(uint64_t) + sizeof(double) + sizeof(float));
}

}  // namespace exitance
