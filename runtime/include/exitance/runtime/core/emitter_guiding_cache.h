// Emitter guiding: guided next-event estimation (issue 11; docs/lighting-core.md "Emitter guiding").
// The scene's emitter triangles are cut into patches (guided_emitters.h), and per record of the
// guiding grid (GuideGridLocator: grid cell x normal class, where texels are) a distribution over
// the patches is learned from the next-event samples themselves and sampled as one component of a
// one-sample mixture with the default next-event sampling.
//
// Learning: a next-event sample at a vertex of record r that lands on patch k with value
// v = luminance(L_e) cos / (pi p) (0 when occluded) is an unbiased estimate of the patch's
// integral of unoccluded direct light over r's vertices, so the sums of v per patch over all
// passes, normalised, are the record's distribution (cumulative, as every pass estimates the same
// integrals). A patch's sum is noisy until several samples have reached it, and a distribution
// that follows a few lucky patches of a visible light samples the rest of that light rarely (the
// building's direct light measured 1.8x the default's variance so). So the sums are pooled per
// cluster of patches (about a light), and inside a cluster the learned shares count with weight
// n / (n + kPseudoSamplesPerPatch x patches), n the cluster's unoccluded samples, the rest spread as
// the default sampling spreads; kFloor of the whole distribution stays the default's. Sums and
// counts are integers added atomically, so they do not depend on thread count or order; swap()
// between passes folds them into the front table that the next pass samples (double buffering, as
// the grid cache).
#pragma once
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "exitance/common/emitter_guide_fold.h"
#include "exitance/common/guided_emitters.h"
#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/guide_grid_locator.h"
#include "exitance/runtime/core/integrator_settings.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

struct EmitterGuidingConfig {
  float mix = 0.5f;                 // the learned component's probability at a record that learned something
  int cells_on_longest_axis = 16;   // the guiding grid (GuideGridLocator)
  uint32_t patch_target = 512;      // about this many patches (fewer when the tables would pass kMemoryBudget)
  uint32_t cluster_target = 64;     // about this many clusters (EmitterPatches::cluster_first)
  // false: the tables are learned and folded elsewhere (the Vulkan backend's device fold): the cache
  // holds no back tables and no learned sums until import_folded brings them (learn, import_learned
  // and swap are then refused).
  bool learns_on_host = true;
};

// The patch tables of an emitter list (guided_emitters.h): built from its power CDF alone.
struct EmitterPatches {
  std::vector<uint32_t> emitter_patch;   // per emitter: first patch << 3 | level
  std::vector<uint32_t> patch_emitters;  // per patch: first emitter, one past its last
  std::vector<float> default_probability;  // per patch: P0
  // Clusters: runs of whole emitters' patches of at most 1 / cluster_target of the power (or one
  // emitter's sub-triangles): patch range [cluster_first[c], cluster_first[c + 1]).
  std::vector<uint32_t> cluster_first;
  uint32_t count() const { return uint32_t(default_probability.size()); }
  uint32_t cluster_count() const { return cluster_first.empty() ? 0u : uint32_t(cluster_first.size() - 1); }
};
EmitterPatches build_emitter_patches(const std::vector<double>& emitter_cdf, uint32_t patch_target,
                                     uint32_t cluster_target);

class EmitterGuidingCache {
 public:
  static constexpr uint32_t kNoRecord = GuideGridLocator::kNoRecord;
  // The fold (common/emitter_guide_fold.h, shared with the device) reads its own copies of these
  // three (a const float there is not a constant expression here): EmitterGuideFold.* checks they agree.
  static constexpr float kFloor = 0.1f;  // of each record's distribution, spread as the default sampling
  static constexpr double kPseudoSamplesPerPatch = 4;
  // A record samples its learned distribution only where that can lower next-event variance enough
  // to pay for the lookups: the direct light's second moment under the default over that under the
  // mixture, were the learned distribution exact, at least this (the Cornell room's records: median
  // 1.07, where the guided lookups cost a quarter of the time; the building's: median 11.7).
  static constexpr double kMinSecondMomentGain = 2.0;
  // Punctual lights are guided when the scene has 2 to this many (one table entry per light per record).
  static constexpr uint32_t kMostGuidedPunctualLights = 1024;
  static constexpr size_t kMemoryBudget = size_t(256) << 20;  // tables of all records together

  EmitterGuidingCache(const LightingScene& scene, const TexelGBuffer& gbuffer, const EmitterGuidingConfig& config);
  // The cache a bake's settings ask for (both CPU estimators): null when settings.emitter_guiding is
  // off or the scene has nothing to guide (no emitter triangle and fewer than two punctual lights).
  static std::unique_ptr<EmitterGuidingCache> for_bake(const LightingScene& scene, const TexelGBuffer& gbuffer,
                                                       const IntegratorSettings& settings, bool learns_on_host = true);
  // Whether `scene` has anything to guide (an emitter triangle or two punctual lights): for_bake
  // makes a cache exactly then, when emitter guiding is on.
  static bool guides(const LightingScene& scene);

  // Which vertices of a texel's sample `sample` teach the tables: every vertex in its first
  // kEveryLearningSamples; after them, one sample in kLaterLearningStride, at vertices whose record
  // samples a learned distribution (they keep improving it). Vertices of records that sample by
  // default then take the default's code path: finding a sample's patch and learning it cost the
  // Cornell room, where every record's gain is small, 11 % of its time when every sample learned.
  // The schedule is guided_emitters.h's emitter_learning_of_sample, shared with the kernels.
  enum class Learning : uint8_t { None = kEmitterLearnNone, Everywhere = kEmitterLearnEverywhere, WhereSampled = kEmitterLearnWhereSampled };
  static constexpr uint32_t kEveryLearningSamples = kEmitterEveryLearningSamples;
  static constexpr uint32_t kLaterLearningStride = kEmitterLaterLearningStride;
  static Learning learning(uint32_t sample) { return Learning(emitter_learning_of_sample(sample)); }
  // Whether path tracing folds the tables (end_pass) once texels hold `samples` samples: at 1, 2, 3,
  // 4, 8, 16, 32 and 64 while every vertex learns, then after every pass. Both backends fold there
  // whatever their pass sizes (a Vulkan pass is bounded by its work items, a CPU pass by the time
  // budget), so the same seed learns the same tables; each fold on the device is a dispatch and a
  // wait (bench/results/emitter-guiding.md: 19 folds to 64 samples became 8).
  static bool folds_after(uint32_t samples) {
    return samples >= kEveryLearningSamples || samples <= 4 || (samples & (samples - 1)) == 0;
  }


  uint32_t record_of(Vec3 position, Vec3 shading_normal) const;

  // The strategy at one path vertex and whether its next-event samples learn (both CPU estimators):
  // a vertex that neither learns nor samples a learned distribution gets emitter_guide_none(), the
  // default's code path. A null cache: the default, learning nothing.
  struct Site {
    uint32_t record = kNoRecord;
    EmitterGuide guide = emitter_guide_none();
    bool learns = false;
  };
  static Site vertex_site(EmitterGuidingCache* cache, Vec3 position, Vec3 shading_normal, Learning learning);
  // After the site's shadow rays: the samples that arrived (path.h EmitterLearning's patch and
  // light, kEmitterPatchNone for none) teach the back tables.
  void learn_arrived(const Site& site, uint32_t patch, float value, bool area_arrived, uint32_t punctual_light,
                     float punctual_value, bool punctual_arrived);
  // The strategy at a vertex of `record`: learned tables (guided_probability 0 until the record has
  // learned something, or while it would gain too little), emitter_guide_none() for kNoRecord.
  EmitterGuide vertex(uint32_t record) const;
  // Adds one next-event sample's value to `patch` of `record` (thread-safe, order-independent).
  void learn(uint32_t record, uint32_t patch, float value);
  // The same for punctual light `light`.
  void learn_punctual(uint32_t record, uint32_t light, float value);
  // Sums another backend learned (the Vulkan kernels' fixed-point sums, guide_fixed_point with
  // fixed_cap() and fixed_units()) into the back tables, as learn() would have added them; folded at
  // the next swap(). Out-of-range indices are ignored.
  void import_learned(uint32_t record, uint32_t patch, uint64_t fixed_sum, uint32_t count);
  void import_learned_punctual(uint32_t record, uint32_t light, uint64_t fixed_sum);
  double fixed_units() const { return fixed_scale_; }
  float fixed_cap() const { return value_cap_; }
  // Per scene triangle its emitter index (kEmitterPatchNone: none): EmitterGuide's triangle table.
  const std::vector<uint32_t>& triangle_emitter() const { return triangle_emitter_; }
  // Between passes: folds the sums learned since the last swap into the front tables.
  void swap();
  // Overwrites `record`'s tables with those a fold elsewhere built (the Vulkan backend's
  // fold_emitter_guide.comp: the same fold, common/emitter_guide_fold.h), so report(), probability()
  // and the inspectors read what that backend sampled: per patch the cumulative learned sums and
  // samples and the CDF (patch_count + 1), per punctual light the learned sums and the CDF
  // (punctual_count + 1), and the two guided probabilities. Null arrays where the count is 0. On a
  // cache made with learns_on_host false its first call allocates the learned tables: call it from
  // one thread.
  void import_folded(uint32_t record, const double* learned, const uint32_t* samples, const float* cdf,
                     float guided_probability, const double* punctual_learned, const float* punctual_cdf,
                     float punctual_guided_probability);
  // The cache stopped where its tables are folded elsewhere (as end_pass stops it here).
  void deactivate() { active_ = false; }
  float mix() const { return config_.mix; }
  const std::vector<float>& punctual_default() const { return punctual_default_; }
  // After a pass that brought texels to `samples` samples each: swap(), and past
  // kEveryLearningSamples, where no record samples a learned distribution (every light seen whole,
  // as in the Cornell room), the cache stops: inactive, its vertices take the default's code path
  // and nothing more is learned or folded.
  void end_pass(uint32_t samples);
  bool active() const { return active_; }
  // What the cache held (for the manifest's stats.emitter_guiding).
  void report(LightmapEstimate::EmitterGuidingReport& out) const;

  // Whether any record samples a learned distribution (area or punctual lights), and how many do.
  bool samples_anywhere() const { return records_sampling_learned() > 0; }
  uint32_t records_sampling_learned() const;
  uint32_t record_count() const { return locator_.record_count(); }
  uint32_t patch_count() const { return patches_.count(); }
  uint32_t punctual_count() const { return punctual_count_; }  // guided punctual lights (0: none)
  const EmitterPatches& patches() const { return patches_; }
  const GuideGridLocator& locator() const { return locator_; }
  // The front distribution's probability of `patch` at `record` (0 where the record samples by default).
  float probability(uint32_t record, uint32_t patch) const;
  float punctual_probability(uint32_t record, uint32_t light) const;  // the same for punctual lights
  size_t memory_bytes() const;

 private:
  // The record's CDFs and guided probabilities from its learned sums (common/emitter_guide_fold.h).
  void rebuild(uint32_t record, const EmitterFoldRecord& rows);
  EmitterFoldRecord fold_record(uint32_t record);
  void allocate_learned();  // learned_, samples_, punctual_learned_ at 0

  EmitterGuidingConfig config_;
  bool active_ = true;
  GuideGridLocator locator_;
  EmitterPatches patches_;
  std::vector<uint32_t> triangle_emitter_;  // per scene triangle
  double fixed_scale_ = 1;                  // fixed-point units per unit of value
  float value_cap_ = 0;
  std::vector<float> guided_probability_;   // per record
  std::vector<float> cdf_;                  // patch_count + 1 per record
  std::vector<double> learned_;             // patch_count per record: cumulative sums of values
  std::vector<uint32_t> samples_;           // patch_count per record: cumulative unoccluded samples
  struct Accumulator {
    std::atomic<uint64_t> sum{0};  // fixed point
    std::atomic<uint32_t> count{0};
  };
  static_assert(sizeof(Accumulator) == 16, "kBytesPerRecordPatch counts 16 bytes per accumulator");
  std::unique_ptr<Accumulator[]> back_;  // patch_count per record
  // Punctual lights: the same per record, without clusters (each light is one).
  uint32_t punctual_count_ = 0;
  std::vector<float> punctual_default_;      // per light: probability by power
  std::vector<float> punctual_guided_probability_;
  std::vector<float> punctual_cdf_;          // punctual_count + 1 per record
  std::vector<double> punctual_learned_;
  std::unique_ptr<std::atomic<uint64_t>[]> punctual_back_;
};

}  // namespace exitance
