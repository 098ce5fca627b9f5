// What a refreshed light probe shows during a light's change estimate (refresh/published_probes.h,
// docs/runtime.md "Probes"): the choice between what it showed, its base and base + change on probes
// whose change samples are explicit lists, so the change's mean and variance are known in closed
// form; and base + change with the dering window per band.
#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>

#include "exitance/common/publishing_rule.h"
#include "published_probes.h"

namespace exitance {
namespace {

// One probe's change from its L0 samples (the same in every channel), every other coefficient's
// mean `rest` per sample.
ProbeEstimate change_of(std::initializer_list<double> l0_samples, double rest = 0.0) {
  ProbeEstimate e;
  e.sh_sum.assign(1, {});
  e.l0_square_sum.assign(1, {});
  e.samples.assign(1, 0);
  e.backface_hits.assign(1, 0);
  for (double s : l0_samples) {
    for (size_t c = 0; c < 3; ++c) {
      e.sh_sum[0][c] += s;
      e.l0_square_sum[0][c] += s * s;
    }
    for (size_t k = 3; k < 27; ++k) e.sh_sum[0][k] += rest;
    ++e.samples[0];
  }
  return e;
}

KeptProbe base_of(float value, uint32_t samples, double variance) {
  KeptProbe b;
  b.sh.fill(value);
  b.samples = samples;
  b.variance = variance;
  return b;
}

TEST(PublishedProbes, AChangeIsShownWhereShowingItHasTheLowerEstimatedError) {
  const KeptProbe base = base_of(1.0f, 512, 0.01);
  // Fewer than 2 change samples: what the probe showed before the edit.
  EXPECT_EQ(probe_change_choice(base, change_of({}), 0), kPublishPrevious);
  EXPECT_EQ(probe_change_choice(base, change_of({5.0}), 0), kPublishPrevious);
  // A change of exactly 0 (no edited light reaches the probe): the base.
  EXPECT_EQ(probe_change_choice(base, change_of({0, 0, 0, 0}), 0), kPublishBase);
  // A steady change of 1 per channel: |d|^2 = 3 against V_d = 0.
  EXPECT_EQ(probe_change_choice(base, change_of({1, 1, 1, 1}), 0), kPublishRefreshed);
  // One spike in 4 samples: d = 2 per channel, sample variance 16, V = 4: |d|^2 = 12 = V_d, not above 2 V_d.
  EXPECT_EQ(probe_change_choice(base, change_of({0, 0, 0, 8}), 0), kPublishBase);
  // A change of 2 +- 1 over 4 samples: |d|^2 = 12, V_d = 3 * (4/3) / 4 = 1 per the three channels.
  EXPECT_EQ(probe_change_choice(base, change_of({1, 3, 1, 3}), 0), kPublishRefreshed);
  // No base sample: what the probe showed.
  EXPECT_EQ(probe_change_choice(base_of(1.0f, 0, -1), change_of({1, 1, 1, 1}), 0), kPublishPrevious);
}

TEST(PublishedProbes, BasePlusChangeAppliesTheDeringWindowToTheChange) {
  const std::array<float, 3> band_weight{1.0f, 0.5f, 0.25f};
  const KeptProbe shown = probe_base_plus_change(base_of(1.0f, 512, 0.01), change_of({0.5, 0.5}, 0.5), 0, band_weight);
  for (size_t i = 0; i < 9; ++i)
    for (size_t c = 0; c < 3; ++c) {
      const float expected = i == 0 ? 1.5f : (i < 4 ? 1.25f : 1.125f);
      EXPECT_EQ(shown.sh[i * 3 + c], expected) << "coefficient " << i << " channel " << c;
    }
  EXPECT_EQ(shown.samples, 512u);
  EXPECT_NEAR(shown.variance, 0.01, 1e-12);  // a steady change adds no variance
  // The change's variance adds to a known base's; an unknown one stays unknown.
  const ProbeEstimate noisy = change_of({1, 3, 1, 3});
  // (each channel's variance of the mean is rounded to float, as publishing_rule.h rounds it)
  EXPECT_NEAR(probe_base_plus_change(base_of(1.0f, 512, 0.01), noisy, 0, band_weight).variance, 0.01 + 1.0, 1e-6);
  EXPECT_EQ(probe_base_plus_change(base_of(1.0f, 512, -1), noisy, 0, band_weight).variance, -1.0);
  // A coefficient whose change is not finite keeps the base's value.
  ProbeEstimate broken = change_of({1, 1});
  broken.sh_sum[0][5] = NAN;
  const KeptProbe kept = probe_base_plus_change(base_of(1.0f, 512, 0.01), broken, 0, band_weight);
  EXPECT_EQ(kept.sh[5], 1.0f);
  EXPECT_EQ(kept.sh[0], 2.0f);
}

}  // namespace
}  // namespace exitance
