// Adaptive sampling per texel without the bias of a stopping rule (issue 12; docs/lighting-core.md,
// "Adaptive sampling").
//
// After a short pilot (the same samples for every texel), the plan gives every texel its sample rate,
// and a texel's rate is computed WITHOUT the texel's own samples: from the pilot samples of its atlas
// neighbours on the same instance (leave-one-out). Given its count, a texel's samples are therefore
// still independent draws and their mean is unbiased. A rule that decided a texel's count from its
// own running estimate (stop when the relative error looks small, or when a texel is still black
// after a few samples) is biased; this one is not, up to the global normalization (one sum over all
// texels) and the time budget, which couple every texel to all others by 1/texels.
//
// The rate follows sigma / ((mean + epsilon) sqrt(cost)), with sigma / (mean + epsilon) the per-sample
// relative standard deviation and cost the rays per sample: the allocation that minimizes the sum of
// relative variances for the time spent; epsilon is a small fraction
// (kErrorFloorFraction) of the scene's mean E/pi so dark texels converge too. A texel whose
// neighbourhood has seen no light at all takes the scene's mean deviation, never a rate of zero, and
// every rate is clamped to [lowest_rate, highest_rate] times the mean.
#pragma once
#include <cstdint>
#include <vector>

#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

// Luminance sums of one texel's pilot samples.
struct TexelSampleSums {
  uint32_t samples = 0;
  uint64_t rays = 0;  // rays the samples traced (their cost)
  double sum = 0;
  double sum_squared = 0;
};

struct AdaptivePlanSettings {
  double floor_fraction = kErrorFloorFraction;  // epsilon = this times the scene's mean luminance of E/pi
  int neighbour_radius = 2;  // atlas texels of the same instance within this Chebyshev distance, self excluded
  double lowest_rate = 0.2;  // rates are clamped to [lowest, highest] times the mean rate
  double highest_rate = 16.0;
};

struct AdaptivePlan {
  std::vector<float> rate;                // per texel, mean 1: samples per unit of progress past the pilot
  std::vector<float> relative_deviation;  // per texel: the per-sample sigma / (mean + epsilon) it came from
  std::vector<float> cost;                // per texel: rays per sample of its neighbourhood (1 without)
  double epsilon = 0;                     // the error floor used (E/pi luminance)
  size_t without_evidence = 0;            // texels whose neighbourhood saw no light: given the mean deviation
};

// The plan after the pilot; `pilot` holds one entry per live texel of `gbuffer`.
AdaptivePlan plan_adaptive_rates(const TexelGBuffer& gbuffer, const std::vector<TexelSampleSums>& pilot,
                                 const AdaptivePlanSettings& settings = {});

// Samples that bring a texel's relative standard error to `target`, from its planned relative
// deviation: sigma^2 / target^2, at least `least`, at most `most`.
uint32_t samples_for_target(float relative_deviation, double target, uint32_t least, uint32_t most);

}  // namespace exitance
