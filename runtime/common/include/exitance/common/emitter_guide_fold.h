// Emitter guiding's fold between passes (issue 11, issue 35; core/emitter_guiding_cache.h has the
// choices), written once for the CPU's EmitterGuidingCache::swap and the Vulkan backend's
// shaders/wavefront/fold_emitter_guide.comp, so tables folded on the device are the host's up to
// float contraction:
//  - a patch's (or punctual light's) cumulative learned sum adds the pass's fixed-point back sum,
//    its cumulative count the pass's unoccluded samples;
//  - a record's area CDF is rebuilt per cluster of patches: the learned shares trusted with weight
//    n / (n + kEmitterFoldPseudoSamplesPerPatch x patches), the rest spread as the default sampling,
//    then mixed with kEmitterFoldFloor of the default; the punctual CDF the same without clusters;
//  - the record samples what it learned (guided probability = mix) only where that would lower the
//    direct light's second moment kEmitterFoldMinSecondMomentGain times, else 0.
// A record's rows are read and written through the accessors below on an EMITTER_FOLD_REF
// (C++: pointers into the cache's arrays; GLSL: the record's index, accessors defined by the
// includer over its buffer); `table` is kEmitterFoldPatches or kEmitterFoldPunctual.
#ifndef EXITANCE_COMMON_EMITTER_GUIDE_FOLD_H
#define EXITANCE_COMMON_EMITTER_GUIDE_FOLD_H
#include "exitance/common/dialect.h"

#ifdef __cplusplus
namespace exitance {
// One record's rows of the cache's tables, and the scene's (shared by all records).
struct EmitterFoldRecord {
  const double* learned;           // per patch: cumulative sum of values
  const uint32_t* samples;         // per patch: cumulative unoccluded samples
  const float* default_probability;  // per patch
  const uint32_t* cluster_first;   // per cluster its first patch, then the patch count
  float* cdf;                      // patch count + 1
  const double* punctual_learned;  // per punctual light
  const float* punctual_default;   // per punctual light
  float* punctual_cdf;             // punctual count + 1
};
inline bool emitter_fold_isfinite(double a) { return std::isfinite(a); }
}  // namespace exitance
#define EMITTER_FOLD_REF const ::exitance::EmitterFoldRecord&
#else
#define EMITTER_FOLD_REF uint
bool emitter_fold_isfinite(double a) { return !isinf(a) && !isnan(a); }
#endif

EXITANCE_NAMESPACE_BEGIN

const uint kEmitterFoldPatches = 0u;
const uint kEmitterFoldPunctual = 1u;
const float kEmitterFoldFloor = 0.1f;                      // of each record's distribution, spread as the default
const double kEmitterFoldPseudoSamplesPerPatch = 4.0;
const double kEmitterFoldMinSecondMomentGain = 2.0;

#ifdef __cplusplus
inline double emitter_fold_learned(EMITTER_FOLD_REF r, uint table, uint k) {
  return table == kEmitterFoldPatches ? r.learned[k] : r.punctual_learned[k];
}
inline uint emitter_fold_samples(EMITTER_FOLD_REF r, uint k) { return r.samples[k]; }
inline float emitter_fold_default(EMITTER_FOLD_REF r, uint table, uint k) {
  return table == kEmitterFoldPatches ? r.default_probability[k] : r.punctual_default[k];
}
inline uint emitter_fold_cluster_first(EMITTER_FOLD_REF r, uint c) { return r.cluster_first[c]; }
inline float emitter_fold_cdf(EMITTER_FOLD_REF r, uint table, uint i) {
  return table == kEmitterFoldPatches ? r.cdf[i] : r.punctual_cdf[i];
}
inline void emitter_fold_write_cdf(EMITTER_FOLD_REF r, uint table, uint i, float value) {
  (table == kEmitterFoldPatches ? r.cdf : r.punctual_cdf)[i] = value;
}
#endif

// One patch's (or light's) back sum (`sum` fixed-point units, `units` per unit of value; `count`
// unoccluded samples, patches only) into its cumulative tables.
EXITANCE_FN void emitter_fold_add(INOUT(double) learned, uint64_t sum, double units) {
  learned += double(sum) / units;
}

// The direct light's second moment under the default over that under the mixture, were the
// learned distribution (the table's CDF, `cells` entries) the light's: how much the mixture can
// lower next-event variance.
EXITANCE_FN double emitter_fold_second_moment_gain(EMITTER_FOLD_REF r, uint table, uint cells, float mix) {
  double under_default = double(0);
  double under_mixture = double(0);
  for (uint k = 0u; k < cells; ++k) {
    double q = double(emitter_fold_cdf(r, table, k + 1u)) - double(emitter_fold_cdf(r, table, k));
    double p0 = double(emitter_fold_default(r, table, k));
    double mixture = double(mix) * q + double(1.0f - mix) * p0;
    if (p0 > double(0)) under_default += q * q / p0;
    if (mixture > double(0)) under_mixture += q * q / mixture;
  }
  return under_mixture > double(0) ? under_default / under_mixture : double(1);
}

// Closes a table's CDF (its last entry 1) and returns its guided probability: `mix` where it learned
// something and that gains enough, else 0.
EXITANCE_FN float emitter_fold_finish(EMITTER_FOLD_REF r, uint table, uint cells, bool learned, float mix) {
  emitter_fold_write_cdf(r, table, cells, 1.0f);
  if (!learned) return 0.0f;
  if (emitter_fold_second_moment_gain(r, table, cells, mix) < kEmitterFoldMinSecondMomentGain) return 0.0f;
  return mix;
}

// One CDF step: the default's probability while nothing is learned, else (1 - floor) x the learned
// share + floor x the default's.
EXITANCE_FN double emitter_fold_step(bool learned, double share, float default_probability) {
  if (!learned) return double(default_probability);
  return (double(1) - double(kEmitterFoldFloor)) * share + double(kEmitterFoldFloor * default_probability);
}

// The punctual lights' CDF from their learned sums; returns their guided probability.
EXITANCE_FN float emitter_fold_rebuild_punctual(EMITTER_FOLD_REF r, uint lights, float mix) {
  double total = double(0);
  for (uint i = 0u; i < lights; ++i) total += emitter_fold_learned(r, kEmitterFoldPunctual, i);
  bool learned = total > double(0) && emitter_fold_isfinite(total);
  double run = double(0);
  emitter_fold_write_cdf(r, kEmitterFoldPunctual, 0u, 0.0f);
  for (uint i = 0u; i < lights; ++i) {
    double share = learned ? emitter_fold_learned(r, kEmitterFoldPunctual, i) / total : double(0);
    run += emitter_fold_step(learned, share, emitter_fold_default(r, kEmitterFoldPunctual, i));
    emitter_fold_write_cdf(r, kEmitterFoldPunctual, i + 1u, float(min(run, double(1))));
  }
  return emitter_fold_finish(r, kEmitterFoldPunctual, lights, learned, mix);
}

// The patches' CDF from their learned sums, pooled per cluster (`clusters` of them, covering the
// `patches` in order); returns their guided probability.
EXITANCE_FN float emitter_fold_rebuild_patches(EMITTER_FOLD_REF r, uint patches, uint clusters, float mix) {
  double total = double(0);
  for (uint k = 0u; k < patches; ++k) total += emitter_fold_learned(r, kEmitterFoldPatches, k);
  bool learned = total > double(0) && emitter_fold_isfinite(total);
  double run = double(0);
  emitter_fold_write_cdf(r, kEmitterFoldPatches, 0u, 0.0f);
  for (uint c = 0u; c < clusters; ++c) {
    uint first = emitter_fold_cluster_first(r, c);
    uint end = emitter_fold_cluster_first(r, c + 1u);
    double cluster_sum = double(0);
    double cluster_default = double(0);
    double cluster_samples = double(0);
    for (uint k = first; k < end; ++k) {
      cluster_sum += emitter_fold_learned(r, kEmitterFoldPatches, k);
      cluster_default += double(emitter_fold_default(r, kEmitterFoldPatches, k));
      cluster_samples += double(emitter_fold_samples(r, k));
    }
    double trust = cluster_samples / (cluster_samples + kEmitterFoldPseudoSamplesPerPatch * double(end - first));
    for (uint k = first; k < end; ++k) {
      float default_probability = emitter_fold_default(r, kEmitterFoldPatches, k);
      double share = double(0);
      if (learned && cluster_sum > double(0)) {
        double spread = cluster_default > double(0) ? double(default_probability) / cluster_default : double(0);
        share = (trust * emitter_fold_learned(r, kEmitterFoldPatches, k) + (double(1) - trust) * cluster_sum * spread) / total;
      }
      run += emitter_fold_step(learned, share, default_probability);
      emitter_fold_write_cdf(r, kEmitterFoldPatches, k + 1u, float(min(run, double(1))));
    }
  }
  return emitter_fold_finish(r, kEmitterFoldPatches, patches, learned, mix);
}

EXITANCE_NAMESPACE_END
#endif
