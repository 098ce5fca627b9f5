// The runtime's publishing rule (refresh/published_estimate.h) on texels whose sums come from
// explicit sample lists, so every mean and variance of the mean is known in closed form.
#include <gtest/gtest.h>

#include <initializer_list>

#include "exitance/runtime/refresh/published_estimate.h"

namespace exitance {
namespace {

// One texel (grey: the three channels equal) from its samples; direct = half of each sample.
LightmapEstimate texel(std::initializer_list<double> samples, int recorded = 2) {
  LightmapEstimate e;
  e.recorded_bounces = recorded;
  e.texels.resize(1);
  e.bounces.assign(size_t(recorded) * 3, 0.0);
  for (double s : samples) {
    TexelAccumulator& t = e.texels[0];
    for (int c = 0; c < 3; ++c) {
      t.total[c] += s, t.total_squared[c] += s * s, t.direct[c] += 0.5 * s;
      e.bounces[size_t(c)] += 0.5 * s;
      e.bounces[3 + size_t(c)] += 0.5 * s;
    }
    ++t.samples;
  }
  return e;
}

TEST(PublishedEstimate, AddChangeAddsMeansLayersAndVariances) {
  const LightmapEstimate base = texel({1, 3, 2, 2});  // mean 2, sample variance 2/3, V = 1/6
  const LightmapEstimate change = texel({-1, 1});     // mean 0, sample variance 2, V = 1
  const LightmapEstimate sum = add_change(base, change);
  EXPECT_EQ(sum.texels[0].samples, 6u);
  EXPECT_NEAR(sum.mean_total(0)[1], 2.0, 1e-6);
  EXPECT_NEAR(sum.variance_of_mean(0)[2], 1.0 / 6 + 1.0, 1e-6);
  EXPECT_NEAR(sum.mean_direct(0)[0], 1.0, 1e-6);
  EXPECT_NEAR(sum.mean_bounce(1, 0)[0], 1.0, 1e-6);
  const LightmapEstimate shifted = add_change(base, texel({4, 6}));  // change mean 5, V = 1
  EXPECT_NEAR(shifted.mean_total(0)[0], 7.0, 1e-6);
  EXPECT_NEAR(shifted.mean_direct(0)[0], 3.5, 1e-6);
  EXPECT_NEAR(shifted.variance_of_mean(0)[0], 1.0 / 6 + 1.0, 1e-5);
  EXPECT_THROW(add_change(base, texel({1, 2}, 3)), std::invalid_argument);
}

TEST(PublishedEstimate, AChangeIsShownWithTwoSamplesWhereShowingItHasTheLowerEstimatedError) {
  const LightmapEstimate previous = texel({5, 5, 5, 5}), base = texel({1, 3, 2, 2});
  // One sample of the change: what the texel showed before the edit, bit for bit.
  EXPECT_EQ(publish_change(previous, base, texel({9})).texels[0].total[0], previous.texels[0].total[0]);
  // Mean 0.5, V = 2.25 per channel: 3 * 0.25 <= 2 * 3 * 2.25: the base exactly.
  EXPECT_EQ(publish_change(previous, base, texel({-1, 2})).texels[0].total[0], base.texels[0].total[0]);
  // Mean 2 from 2 samples, V = 1: 3 * 4 > 2 * 3 * 1, base + change.
  EXPECT_NEAR(publish_change(previous, base, texel({1, 3})).mean_total(0)[0], 4.0, 1e-6);
  // One spike among n samples has |d|^2 = V_d, whatever n: never shown; two are (mean 3, V = 3:
  // 27 > 2 * 9).
  EXPECT_EQ(publish_change(previous, base, texel({0, 0, 0, 6})).texels[0].total[0], base.texels[0].total[0]);
  EXPECT_EQ(publish_change(previous, base, texel({0, 0, 0, 0, 0, 0, 0, 0, 0, 6})).texels[0].total[0], base.texels[0].total[0]);
  EXPECT_NEAR(publish_change(previous, base, texel({0, 0, 6, 6})).mean_total(0)[0], 5.0, 1e-6);
  // A change exactly 0 (no edited light reaches the texel): the base exactly.
  EXPECT_EQ(publish_change(previous, base, texel({0, 0, 0})).texels[0].total[1], base.texels[0].total[1]);
}

TEST(PublishedEstimate, AChangeBaseNeedsVariances) {
  EXPECT_TRUE(can_be_change_base(texel({1, 2})));
  EXPECT_FALSE(can_be_change_base(texel({1})));
  EXPECT_FALSE(can_be_change_base(texel({})));
}

TEST(PublishedEstimate, ARestartKeepsThePreviousValueUntilTheRefreshedOneIsMorePreciseOrSignificantlyDifferent) {
  const LightmapEstimate previous = texel({1, 3, 2, 2});  // mean 2, V = 1/6
  // Nothing before: the refreshed estimate, even with one sample.
  EXPECT_NEAR(publish_restart(texel({}), texel({7})).mean_total(0)[0], 7.0, 1e-6);
  // Fewer than kRestartMinimumSamples refreshed samples: the previous value, even far from it.
  EXPECT_EQ(publish_restart(previous, texel({7})).texels[0].total[0], previous.texels[0].total[0]);
  const LightmapEstimate eight = texel({1, 3, 2, 2, 1, 3, 2, 2});
  EXPECT_EQ(publish_restart(eight, texel({9, 11, 9, 11, 9, 11, 10})).texels[0].total[0], eight.texels[0].total[0]);
  // A kept value of 4 samples is replaced after 4 refreshed ones, where they differ significantly
  // (3 * 64 > 9.22^2 * 3 * (1/3 + 1/3): 3 standard errors widened for variances from 4 samples).
  const LightmapEstimate four = texel({1, 3, 1, 3});  // mean 2, V = 1/3
  EXPECT_NEAR(publish_restart(four, texel({9, 11, 9, 11})).mean_total(0)[0], 10.0, 1e-6);
  // ...but not a difference of about 5 standard errors, significant only were the variances known.
  EXPECT_EQ(publish_restart(four, texel({5, 7, 5, 7})).texels[0].total[0], four.texels[0].total[0]);
  // A kept value of one sample has no variance: two refreshed samples replace it.
  EXPECT_NEAR(publish_restart(texel({2}), texel({4, 6})).mean_total(0)[0], 5.0, 1e-6);
  // Eight refreshed samples with a smaller variance than a kept value of 16 (less precise as the
  // counts go, the variance from 8 samples being too uncertain): kept.
  const LightmapEstimate sixteen = texel({1, 3, 1, 3, 1, 3, 1, 3, 1, 3, 1, 3, 1, 3, 1, 3});  // V = 1/15
  EXPECT_EQ(publish_restart(sixteen, texel({2, 2, 2, 2, 2, 2, 2, 2.5})).texels[0].total[0], sixteen.texels[0].total[0]);
  // Eight refreshed samples that happen to agree (3.5 each: no variance of their own) against a kept
  // value of 16 whose samples vary: the refreshed variance is taken as at least what the kept
  // samples predict for 8 (2/15), so 3 * 1.5^2 = 6.75 < 4.53^2 * 3 * (1/15 + 2/15) = 12.3: kept.
  EXPECT_EQ(publish_restart(sixteen, texel({3.5, 3.5, 3.5, 3.5, 3.5, 3.5, 3.5, 3.5})).texels[0].total[0], sixteen.texels[0].total[0]);
  // Far enough (mean 5: 27 > 12.3): refreshed.
  EXPECT_NEAR(publish_restart(sixteen, texel({5, 5, 5, 5, 5, 5, 5, 5})).mean_total(0)[0], 5.0, 1e-6);
  EXPECT_EQ(publish_restart(four, texel({9, 11, 10})).texels[0].total[0], four.texels[0].total[0]);
  // Same mean, larger variance (V = 4/7): kept.
  EXPECT_EQ(publish_restart(previous, texel({0, 4, 0, 4, 0, 4, 0, 4})).texels[0].total[0], previous.texels[0].total[0]);
  // Same mean, smaller variance (V = 1/24 from 8 samples): refreshed.
  EXPECT_NEAR(publish_restart(previous, texel({1.5, 2.5, 2, 2, 1.5, 2.5, 2, 2})).variance_of_mean(0)[0], 1.0 / 56, 1e-6);
  // Mean 2.9, V = 4/7: 3 * 0.81 < 9 * 3 * (1/6 + 4/7): not significant, less precise: kept.
  EXPECT_EQ(publish_restart(previous, texel({0.9, 4.9, 0.9, 4.9, 0.9, 4.9, 0.9, 4.9})).texels[0].total[0], previous.texels[0].total[0]);
  // Far from the previous value (mean 10): the difference dwarfs both variances: refreshed.
  EXPECT_NEAR(publish_restart(previous, texel({9, 11, 9, 11, 9, 11, 9, 11})).mean_total(0)[0], 10.0, 1e-6);
}

// A texel the edit covered: every refreshed sample exactly 0. Under "nothing changed" a sample of
// the kept value (non-negative, mean K, per-sample variance s^2 summed over the channels) is 0 with
// probability at most s^2 / (s^2 + |K|^2), so n zeros have at most its n-th power.
TEST(PublishedEstimate, ARestartShowsACoveredTexelOnceItsRunOfZerosIsImprobableUnchanged) {
  const std::initializer_list<double> zeros8 = {0, 0, 0, 0, 0, 0, 0, 0};
  // Kept: 16 samples of 1 and 3 (mean 2, s^2 = 3 x 16/15 = 3.2, |K|^2 = 12): a zero has probability
  // at most 0.21, eight of them 3.9e-6 < 0.0027: refreshed. The 3-sigma test alone keeps it
  // (12 < 4.53^2 x (1/5 + 2/5) = 12.3).
  const LightmapEstimate sixteen = texel({1, 3, 1, 3, 1, 3, 1, 3, 1, 3, 1, 3, 1, 3, 1, 3});
  EXPECT_EQ(publish_restart(sixteen, texel(zeros8)).texels[0].samples, 8u);
  EXPECT_EQ(publish_restart(sixteen, texel(zeros8)).texels[0].total[0], 0.0);
  // Eight samples of 0 but one (0.01): not a run of zeros, and not significant: kept.
  EXPECT_EQ(publish_restart(sixteen, texel({0, 0, 0, 0, 0, 0, 0, 0.01})).texels[0].total[0], sixteen.texels[0].total[0]);
  // Kept samples that are often 0 (0, 0, 0, 4: mean 1, s^2 = 3 x 3.2 = 9.6, |K|^2 = 3): a zero has
  // probability at most 0.76 unchanged, eight of them 0.11: kept; 24 of them 0.0015: refreshed.
  const LightmapEstimate often_dark = texel({0, 0, 0, 4, 0, 0, 0, 4, 0, 0, 0, 4, 0, 0, 0, 4});
  EXPECT_EQ(publish_restart(often_dark, texel(zeros8)).texels[0].total[0], often_dark.texels[0].total[0]);
  LightmapEstimate zeros24 = texel(zeros8);
  zeros24.texels[0].samples = 24;
  EXPECT_EQ(publish_restart(often_dark, zeros24).texels[0].samples, 24u);
  // A kept value of 0 stays whatever the zeros (nothing to replace).
  const LightmapEstimate dark = texel({0, 0, 0, 0});
  EXPECT_EQ(publish_restart(dark, texel(zeros8)).texels[0].samples, 4u);
}

}  // namespace
}  // namespace exitance
