// What a texel publishes while the runtime refreshes (docs/runtime.md "Never worse than before the
// edit"): the decision per texel, one text for the host (refresh/published_estimate.cpp) and the
// device (shaders/wavefront/publish.comp). The value a texel showed before an edit estimates the
// edited scene too, exact where the edit changed nothing and biased by the change elsewhere; the
// refreshed estimate is unbiased but noisy. A texel keeps its previous value unless the refreshed
// estimate is the more precise one or differs from it significantly: |D|^2 > kSignificance^2 V_D,
// with D the difference of the two and V_D its variance (variances of the mean, summed over the
// colour channels).
#ifndef EXITANCE_COMMON_PUBLISHING_RULE_H
#define EXITANCE_COMMON_PUBLISHING_RULE_H
#include "exitance/common/dialect.h"
EXITANCE_NAMESPACE_BEGIN

// Standard errors of the difference beyond which a refreshed estimate replaces a kept value (3: an
// unchanged texel switches about 0.3 % of the time for Gaussian noise).
const double kSignificance = 3.0;
// Samples a restarted estimate needs before it may replace a kept value, or as many as the kept
// value had if that is fewer (at least 2): a variance from 2 samples is below a tenth of the true
// one a quarter of the time, while an object moved every frame and refreshed a few samples per
// frame must still show its moves.
const uint kRestartMinimumSamples = 8u;

// What a texel publishes.
const uint kPublishPrevious = 0u;   // what it showed before the last edit
const uint kPublishBase = 1u;       // a change estimate's base (the change is not significant)
const uint kPublishRefreshed = 2u;  // the refreshed estimate (after a change: base + change)

// The variance of the mean of one channel from its sums over n >= 2 samples, as
// LightmapEstimate::variance_of_mean rounds it (0 below 2 samples).
EXITANCE_FN float variance_of_mean_from_sums(double total, double total_squared, uint samples) {
  if (samples < 2u) return 0.0f;
  double n = double(samples);
  double mean = total / n;
  double sample_variance = max(double(0), (total_squared - n * mean * mean) / (n - double(1)));
  return float(sample_variance / n);
}

// After a restart: `refreshed` accumulated from nothing, independent of the kept value.
// difference_squared = |F - K|^2 and the variances are summed over the channels.
EXITANCE_FN uint publish_after_restart(uint kept_samples, uint refreshed_samples, double difference_squared,
                                       double kept_variance, double refreshed_variance) {
  if (kept_samples == 0u) return kPublishRefreshed;  // nothing before: whatever the refresh has
  if (refreshed_samples < max(2u, min(kRestartMinimumSamples, kept_samples))) return kPublishPrevious;
  bool significant = difference_squared > kSignificance * kSignificance * (kept_variance + refreshed_variance);
  return (refreshed_variance < kept_variance || significant) ? kPublishRefreshed : kPublishPrevious;
}

// After light edits estimated as a change d from a base (what was shown before the first of them):
// the previous value while the change has fewer than 2 samples (or the base none), then base + d
// where d is significant (|d|^2 > kSignificance^2 V_d: the rule with kept = base and D = d sharing
// the base), else the base.
EXITANCE_FN uint publish_after_change(uint base_samples, uint change_samples, double change_squared, double change_variance) {
  if (change_samples < 2u || base_samples == 0u) return kPublishPrevious;
  return change_squared > kSignificance * kSignificance * change_variance ? kPublishRefreshed : kPublishBase;
}

EXITANCE_NAMESPACE_END
#endif
