// Grid guiding's fold between passes (issue 11, issue 35; core/grid_guiding_cache.h has the
// choices), written once for the CPU's GridGuidingCache::swap and the Vulkan backend's
// shaders/wavefront/fold_guide.comp, so a table folded on the device is the host's up to float
// contraction:
//  - each bin's learned radiance is the cumulative mean of its targets (kGuideCountDecay keeps old
//    counts whole: passes are a few spp and halving per swap left ~4 samples behind a bin);
//  - a record's CDF is rebuilt from its bins shrunk toward the record's mean by kGuidePriorSamples
//    pseudo-samples (one lucky emitter hit does not draw the sampler), plus a uniform floor of
//    kGuideUniformFloor of the mass so no bin has probability 0.
// A record's tables are read and written through guide_fold_radiance / guide_fold_weight /
// guide_fold_write_cdf on a GUIDE_FOLD_REF (C++: pointers into the cache's arrays; GLSL: the
// record's index, accessors defined by the includer over its buffer).
#ifndef EXITANCE_COMMON_GUIDE_FOLD_H
#define EXITANCE_COMMON_GUIDE_FOLD_H
#include "exitance/common/guided_direction.h"

#ifdef __cplusplus
namespace exitance {
// One record's rows of the cache's learned radiance, weights and CDF.
struct GuideFoldRecord {
  const float* radiance;  // kGuideBins
  const float* weight;    // kGuideBins
  float* cdf;             // kGuideBins + 1
};
inline float guide_fold_radiance(const GuideFoldRecord& r, uint bin) { return r.radiance[bin]; }
inline float guide_fold_weight(const GuideFoldRecord& r, uint bin) { return r.weight[bin]; }
inline void guide_fold_write_cdf(const GuideFoldRecord& r, uint i, float value) { r.cdf[i] = value; }
inline bool isfinite_double(double a) { return std::isfinite(a); }
}  // namespace exitance
#define GUIDE_FOLD_REF const ::exitance::GuideFoldRecord&
#else
#define GUIDE_FOLD_REF uint
bool isfinite_double(double a) { return !isinf(a) && !isnan(a); }
#endif

EXITANCE_NAMESPACE_BEGIN

const float kGuideCountDecay = 1.0f;
const float kGuidePriorSamples = 8.0f;
const float kGuideUniformFloor = 0.02f;

// One bin's back sums (fixed-point `sum` in `units` per unit of radiance, `count` targets) folded
// into its learned radiance and weight. Returns whether the bin learned anything.
EXITANCE_FN bool guide_fold_bin(INOUT(float) radiance, INOUT(float) weight, uint64_t sum, uint count, double units) {
  weight *= kGuideCountDecay;
  if (count == 0u) return false;
  float mean = float(double(sum) / units / double(count));
  float w = weight + float(count);
  radiance += (mean - radiance) * (float(count) / w);
  weight = w;
  return true;
}

// A bin's radiance shrunk toward its record's mean `prior`.
EXITANCE_FN double guide_fold_shrunk(GUIDE_FOLD_REF record, uint bin, double prior) {
  double w = double(guide_fold_weight(record, bin));
  double shrink = double(kGuidePriorSamples);
  return (w * double(guide_fold_radiance(record, bin)) + shrink * prior) / (w + shrink);
}

// What a vertex of the record reads besides its CDF: the cosine-weighted mean of its learned
// radiance (Lbar) and the guided share of its mixture (`mix`, or 0 while nothing is learned).
struct GuideFoldFront {
  float expected_cosine;
  float guided_probability;
};

// The record's CDF rebuilt from its learned bins; returns its front values.
EXITANCE_FN GuideFoldFront guide_fold_rebuild(GUIDE_FOLD_REF record, float mix) {
  double weighted = double(0);
  double weights = double(0);
  for (uint b = 0u; b < kGuideBins; ++b) {
    double w = double(guide_fold_weight(record, b));
    weighted += w * double(guide_fold_radiance(record, b));
    weights += w;
  }
  double prior = weights > double(0) ? weighted / weights : double(0);
  double total = double(0);
  for (uint b = 0u; b < kGuideBins; ++b) total += guide_fold_shrunk(record, b, prior);
  bool learned = total > double(0) && isfinite_double(total);
  GuideFoldFront front;
  // (1/pi) * integral of L cos = (1/pi) * sum of L_b * (pi / bins): every bin has cosine mass pi / bins.
  front.expected_cosine = learned ? float(total / double(kGuideBins)) : 0.0f;
  front.guided_probability = learned ? mix : 0.0f;
  double guided_share = double(1) - double(kGuideUniformFloor);
  double floor_share = double(kGuideUniformFloor / float(kGuideBins));
  double run = double(0);
  guide_fold_write_cdf(record, 0u, 0.0f);
  for (uint b = 0u; b < kGuideBins; ++b) {
    double share = learned ? guide_fold_shrunk(record, b, prior) / total : double(0);
    run += guided_share * share + floor_share;
    guide_fold_write_cdf(record, b + 1u, float(min(run, double(1))));
  }
  guide_fold_write_cdf(record, kGuideBins, 1.0f);
  return front;
}

EXITANCE_NAMESPACE_END
#endif
