// What a texel publishes while the runtime refreshes (docs/runtime.md "Never worse than before the
// edit"): the decision per texel, one text for the host (refresh/published_estimate.cpp) and the
// device (shaders/wavefront/publish.comp). The value a texel showed before an edit estimates the
// edited scene too, exact where the edit changed nothing and biased by the change elsewhere; the
// refreshed estimate is unbiased but noisy. After a restart a texel keeps its previous value unless
// the refreshed estimate is the more precise one (lower variance from at least as many samples) or
// differs from it significantly: |D|^2 > k(n)^2 V_D, with D the difference of the two, V_D its
// variance (variances of the mean, summed over the colour channels; the refreshed part at least what
// the kept samples' variance predicts for its sample count) and k(n) kSignificance widened for a
// variance estimated from n samples (significance_for_samples). A change estimate (light edits) is
// shown by its own rule, publish_after_change.
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

// kSignificance for a variance estimated from `samples` (n >= 2) rather than known: the Student-t
// quantile with n - 1 degrees of freedom that leaves the Gaussian kSignificance's tail mass (0.27 %
// two-sided). A few samples of a path-traced texel often miss its rare bright paths, so their
// variance is too small, and unchanged texels would pass a plain 3-sigma test far more often than
// 0.3 % (measured: the open city's block move, 6 frames, relMSE 0.0052 against 0.0027 kept).
// Exact for 1-3 degrees of freedom, the Cornish-Fisher expansion (5 terms, within 1 % at 4) above.
EXITANCE_FN double significance_for_samples(uint samples) {
  if (samples < 2u) return 1e30;
  double nu = double(samples - 1u);
  if (samples == 2u) return 235.8;
  if (samples == 3u) return 19.21;
  if (samples == 4u) return 9.219;
  double z = kSignificance;
  double z2 = z * z;
  double z3 = z2 * z, z5 = z3 * z2, z7 = z5 * z2, z9 = z7 * z2;
  return z + (z3 + z) / (4.0 * nu) + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * nu * nu) +
         (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / (384.0 * nu * nu * nu) +
         (79.0 * z9 + 776.0 * z7 + 1482.0 * z5 - 1920.0 * z3 - 945.0 * z) / (92160.0 * nu * nu * nu * nu);
}

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

// The two-sided tail mass of kSignificance standard errors of a Gaussian: how improbable a run of
// refreshed samples must be under "nothing changed" to replace a kept value by the test below.
const float kUnchangedRunProbability = 0.0027f;

// base^exponent by squaring: the same float products on the host and the device.
EXITANCE_FN float power_of(float base, uint exponent) {
  float result = 1.0f;
  float b = base;
  uint e = exponent;
  while (e > 0u) {
    if ((e & 1u) != 0u) result *= b;
    b *= b;
    e = e >> 1u;
  }
  return result;
}

// After a restart: `refreshed` accumulated from nothing, independent of the kept value.
// difference_squared = |F - K|^2 and the variances are summed over the channels.
// `refreshed_all_zero`: every refreshed sample was exactly 0 (its sums are 0).
EXITANCE_FN uint publish_after_restart(uint kept_samples, uint refreshed_samples, double difference_squared,
                                       double kept_variance, double refreshed_variance, bool refreshed_all_zero) {
  if (kept_samples == 0u) return kPublishRefreshed;  // nothing before: whatever the refresh has
  if (refreshed_samples < max(2u, min(kRestartMinimumSamples, kept_samples))) return kPublishPrevious;
  if (kept_samples < 2u) return kPublishRefreshed;  // one kept sample has no variance: two refreshed ones are better
  // A texel the edit covered (every path now ends on the back of a surface or in the dark): all its
  // refreshed samples are 0 while the kept value K is not. The test below cannot see that in a few
  // samples (their variance is 0, the floor from the kept samples' spread hides the difference), yet
  // under "nothing changed" a sample, non-negative with mean K and per-sample variance s^2, is 0 with
  // probability at most s^2 / (s^2 + |K|^2) (Cantelli's inequality, summed over the channels), so n
  // zeros have at most that to the n-th: below kUnchangedRunProbability the texel changed. (Measured:
  // the open city's moved block on lavapipe, 17 samples; bench/results/refresh-change.md.)
  if (refreshed_all_zero && difference_squared > 0.0) {
    double spread = kept_variance * double(kept_samples);
    float zero_probability = float(spread / (spread + difference_squared));
    if (power_of(zero_probability, refreshed_samples) < kUnchangedRunProbability) return kPublishRefreshed;
  }
  double k = significance_for_samples(min(kept_samples, refreshed_samples));
  // Where the edit changed nothing, the refreshed estimate's per-sample variance is the kept one's,
  // which many kept samples measure far better than a few refreshed ones (those miss the rare bright
  // paths): the refreshed variance is taken as at least the kept per-sample variance over its samples.
  double expected_variance = kept_variance * double(kept_samples) / double(refreshed_samples);
  bool significant = difference_squared > k * k * (kept_variance + max(refreshed_variance, expected_variance));
  bool more_precise = refreshed_samples >= kept_samples && refreshed_variance < kept_variance;
  return (more_precise || significant) ? kPublishRefreshed : kPublishPrevious;
}

// What a refreshed light probe shows (refresh/published_probes.h on the host, publish_probes.comp on
// the device): its refreshed estimate of n samples rather than what it showed before the last edit
// (kept_samples behind that, its L0 mean's variance summed over rgb; < 0 when unknown, as for the
// bundle's probes.bin: then the refreshed estimate once it has switch_samples), by
// publish_after_restart on the probe's L0 terms.
EXITANCE_FN bool publish_probe_refreshed(uint n, uint switch_samples, uint kept_samples, double kept_variance,
                                         double difference_squared, double refreshed_variance, bool refreshed_all_zero) {
  if (n == 0u) return false;
  if (kept_variance < 0.0) return n >= switch_samples;
  return publish_after_restart(kept_samples, n, difference_squared, kept_variance, refreshed_variance, refreshed_all_zero) ==
         kPublishRefreshed;
}

// A change estimate's d is shown where |d|^2 > kChangeShownAbove V_d. Showing base + d costs its
// variance V_d; showing the base costs the true change squared, whose estimate from d is
// |d|^2 - V_d: so 2 is where the estimated errors are equal. Unlike a restart's independent
// estimate, a change estimate is exactly 0 wherever no edited light reaches a path, and a texel
// whose samples hold one spike (|d|^2 = V_d for any sample count) is never shown, so no widening for
// few samples is needed. Measured (bench/results/refresh-change.md "Showing a change"): against the
// 3-sigma test widened for few samples, relMSE after one frame of 4 / 15 / 60 samples 0.103 / 0.035 /
// 0.0089 instead of 1.67 / 0.048 / 0.024 (a sun turned) and 0.0044 / 0.0039 / 0.0023 instead of
// 0.0070 / 0.0046 / 0.0033 (a point light moved; unrefreshed 0.0080).
const double kChangeShownAbove = 2.0;

// After light edits estimated as a change d from a base (what was shown before the first of them):
// the previous value while the change has fewer than 2 samples (or the base none), then base + d
// where |d|^2 > kChangeShownAbove V_d (summed over the channels), else the base.
EXITANCE_FN uint publish_after_change(uint base_samples, uint change_samples, double change_squared, double change_variance) {
  if (change_samples < 2u || base_samples == 0u) return kPublishPrevious;
  return change_squared > kChangeShownAbove * change_variance ? kPublishRefreshed : kPublishBase;
}

EXITANCE_NAMESPACE_END
#endif
