// refresh::PassCost (runtime/include/exitance/runtime/refresh/pass_cost.h), which sizes the
// runtime's refresh passes to a frame's milliseconds: a clean linear cost is fitted exactly, and a
// fit from two small passes whose times are mostly noise (a slope near 0) cannot size the next pass
// beyond kMaxGrowth times the largest pass measured (before: 738 samples for a 16 ms frame, 825 ms,
// on an H200).
#include <gtest/gtest.h>

#include "exitance/runtime/refresh/pass_cost.h"

using exitance::refresh::PassCost;

namespace {
constexpr size_t kTexels = 391530;  // ajar_room at 64 texels/m
}

TEST(PassCost, FitsALinearCostAndSizesPassesToTheBudget) {
  PassCost cost{kTexels};
  const double fixed = 2.0, per_sample = 0.25;  // ms
  for (double samples : {1.0, 2.0, 8.0, 32.0}) cost.add(samples * kTexels, fixed + per_sample * samples);
  EXPECT_TRUE(cost.fitted);
  EXPECT_NEAR(cost.fixed_ms, fixed, 1e-9);
  EXPECT_NEAR(cost.ms_per_work * kTexels, per_sample, 1e-12);
  // 16 ms: (16 - 2) / 0.25 = 56 samples, within 4x the largest pass (32 samples).
  EXPECT_EQ(cost.fitting(16.0, kTexels), 56.0);
  // 1 s would fit 3992, but the largest pass measured was 32 samples: at most 128.
  EXPECT_EQ(cost.fitting(1000.0, kTexels), 128.0);
}

TEST(PassCost, ANoisyFitOfSmallPassesCannotSizeAHugePass) {
  PassCost cost{kTexels};
  // 3 samples in 5.00 ms, then 4 in 5.02 ms: the fit says 0.02 ms per sample and 4.94 ms fixed,
  // so 16 ms "fit" 553 samples; the true cost is ~1 ms per sample.
  cost.add(3.0 * kTexels, 5.00);
  cost.add(4.0 * kTexels, 5.02);
  ASSERT_TRUE(cost.fitted);
  EXPECT_LT(cost.ms_per_work * kTexels, 0.05);
  const double samples = cost.fitting(16.0, kTexels);
  EXPECT_EQ(samples, 16.0) << "at most kMaxGrowth x the largest pass (4 samples)";
  // A pass over part of a list (one sample of as many texels as fit) has the same cap.
  EXPECT_EQ(cost.fitting_texels(16.0), 16.0 * kTexels);
  // That pass, measured at its true cost, refits the model: the next one is sized from it.
  cost.add(samples * kTexels, 4.0 + 1.0 * samples);
  EXPECT_NEAR(cost.ms_per_work * kTexels, (20.0 - 5.02) / 12.0, 1e-9);
  EXPECT_LE(cost.fitting(16.0, kTexels), 16.0);
}

TEST(PassCost, APriorFromAnotherListKeepsTheCap) {
  PassCost cost{kTexels};
  cost.add(1.0 * kTexels, 3.0);
  cost.add(2.0 * kTexels, 3.1);  // a slope near 0 again
  // The texels near an edit: 10 000 of them, with the whole lightmap's cost as their prior.
  const PassCost near = cost.for_list(10000);
  EXPECT_TRUE(near.prior);
  EXPECT_LE(near.fitting(16.0, 10000) * 10000.0, 4.0 * 2.0 * kTexels) << "at most 4x the largest pass";
  EXPECT_GE(near.fitting(16.0, 10000), 1.0);
}
