// The adaptive plan (core/adaptive_sampling_plan.h) on hand-made pilots: a texel's rate never reads
// its own samples (the property that keeps the estimate unbiased), an all-black neighbourhood gets
// the mean rate rather than none, rates follow the deviation and the cost within their clamp, other
// instances are not neighbours, and the target-error count is sigma^2 / target^2.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "exitance/runtime/core/adaptive_sampling_plan.h"

namespace exitance {
namespace {

// One page of width x height texels, all live, instance 0 left of `split_x` and 1 from it.
TexelGBuffer grid(int width, int height, int split_x = 1 << 30) {
  TexelGBuffer g;
  AtlasPage page;
  page.width = width, page.height = height;
  page.coverage.assign(size_t(width) * size_t(height), 1.0f);
  g.pages.push_back(page);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      LiveTexel t;
      t.x = uint32_t(x), t.y = uint32_t(y);
      t.instance = x < split_x ? 0 : 1;
      g.texels.push_back(t);
    }
  return g;
}

// Pilot sums of `n` samples with mean m and per-sample variance v (rays per sample r).
TexelSampleSums sums(uint32_t n, double m, double v, double r = 3) {
  TexelSampleSums s;
  s.samples = n;
  s.sum = n * m;
  s.sum_squared = n * (v * (n - 1.0) / n + m * m);
  s.rays = uint64_t(r * n);
  return s;
}

double mean_of(const std::vector<float>& v) {
  double sum = 0;
  for (float x : v) sum += x;
  return sum / double(v.size());
}

TEST(AdaptivePlan, TexelRateIgnoresItsOwnSamples) {
  const TexelGBuffer g = grid(8, 8);
  std::vector<TexelSampleSums> pilot;
  for (size_t i = 0; i < g.texels.size(); ++i) pilot.push_back(sums(16, 1.0 + 0.1 * double(i % 5), 0.5 + 0.2 * double(i % 7)));
  const AdaptivePlan before = plan_adaptive_rates(g, pilot);
  // Texel 27's own spread and cost change wildly (its mean, hence the error floor, stays).
  const size_t own = 27;
  pilot[own] = sums(16, pilot[own].sum / 16, 400.0, 40);
  const AdaptivePlan after = plan_adaptive_rates(g, pilot);
  EXPECT_EQ(after.relative_deviation[own], before.relative_deviation[own]);
  EXPECT_EQ(after.cost[own], before.cost[own]);
  EXPECT_EQ(after.epsilon, before.epsilon);
  // ...while its neighbours read it (the test can see a dependence where there is one).
  EXPECT_GT(after.relative_deviation[own + 1], 2 * before.relative_deviation[own + 1]);
  EXPECT_GT(after.cost[own + 1], before.cost[own + 1]);
}

TEST(AdaptivePlan, BlackNeighbourhoodGetsTheMeanDeviationNotZero) {
  const TexelGBuffer g = grid(16, 4);
  std::vector<TexelSampleSums> pilot(g.texels.size());
  for (size_t i = 0; i < g.texels.size(); ++i)
    pilot[i] = g.texels[i].x < 8 ? sums(16, 0.0, 0.0) : sums(16, 2.0, 1.0);
  const AdaptivePlan plan = plan_adaptive_rates(g, pilot);
  // x = 0..5 see only black neighbours (radius 2): no evidence, so the mean of the others.
  EXPECT_EQ(plan.without_evidence, size_t(6 * 4));
  const float lit = plan.relative_deviation[size_t(0) * 16 + 12];
  EXPECT_GT(lit, 0.0f);
  for (int x = 0; x < 6; ++x) EXPECT_GT(plan.rate[size_t(x)], 0.5f) << "x " << x;
  EXPECT_NEAR(mean_of(plan.rate), 1.0, 1e-5);
}

TEST(AdaptivePlan, RatesFollowDeviationOverRootCostWithinTheClamp) {
  const TexelGBuffer g = grid(30, 6);
  std::vector<TexelSampleSums> pilot(g.texels.size());
  // Three bands of 10 columns: relative deviation 1, 3 (same cost) and 3 at 9x the cost.
  for (size_t i = 0; i < g.texels.size(); ++i) {
    const uint32_t band = g.texels[i].x / 10;
    pilot[i] = band == 0 ? sums(64, 1.0, 1.0 * 1.0) : sums(64, 1.0, 9.0, band == 1 ? 3.0 : 27.0);
  }
  AdaptivePlanSettings settings;
  settings.floor_fraction = 0;  // plain sigma / mean, to compare with the closed form
  const AdaptivePlan plan = plan_adaptive_rates(g, pilot, settings);
  auto rate_at = [&](int x) { return plan.rate[size_t(3) * 30 + size_t(x)]; };
  // Interior texels of each band (neighbourhoods inside one band).
  EXPECT_NEAR(rate_at(15) / rate_at(5), 3.0, 0.15);
  EXPECT_NEAR(rate_at(25) / rate_at(15), 1.0 / 3.0, 0.02);
  EXPECT_NEAR(mean_of(plan.rate), 1.0, 1e-5);
  // Clamp: one texel 10^4 times noisier than the rest stays within highest / lowest of the others.
  pilot.assign(g.texels.size(), sums(64, 1.0, 1.0));
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) pilot[size_t(3 + dy) * 30 + size_t(15 + dx)] = sums(64, 1.0, 1e8);
  const AdaptivePlan clamped = plan_adaptive_rates(g, pilot);
  const auto [lo, hi] = std::minmax_element(clamped.rate.begin(), clamped.rate.end());
  EXPECT_LE(*hi / *lo, AdaptivePlanSettings{}.highest_rate / AdaptivePlanSettings{}.lowest_rate * (1 + 1e-5));
  EXPECT_GT(*hi / *lo, 10.0);
}

TEST(AdaptivePlan, OtherInstancesAreNotNeighbours) {
  const TexelGBuffer g = grid(10, 5, 5);
  std::vector<TexelSampleSums> pilot(g.texels.size());
  for (size_t i = 0; i < g.texels.size(); ++i) pilot[i] = g.texels[i].instance == 0 ? sums(16, 1, 1) : sums(16, 1, 100);
  const AdaptivePlan plan = plan_adaptive_rates(g, pilot);
  // Column 4 (instance 0) touches instance 1 at column 5: its deviation is still instance 0's (up to
  // the pooled variance's n / (n - 1), which depends on how many neighbours a texel has: < 1 %).
  auto deviation = [&](int x) { return plan.relative_deviation[size_t(2) * 10 + size_t(x)]; };
  EXPECT_NEAR(deviation(4), deviation(1), 0.01 * deviation(1));
  EXPECT_NEAR(deviation(5), deviation(8), 0.01 * deviation(8));
  EXPECT_GT(deviation(5), 5 * deviation(4));
}

TEST(AdaptivePlan, TargetCountIsDeviationSquaredOverTargetSquared) {
  EXPECT_EQ(samples_for_target(1.0f, 0.1, 16, 1u << 20), 100u);
  EXPECT_EQ(samples_for_target(2.0f, 0.05, 16, 1u << 20), 1600u);
  EXPECT_EQ(samples_for_target(0.1f, 0.1, 16, 1u << 20), 16u);     // at least the pilot
  EXPECT_EQ(samples_for_target(100.0f, 0.001, 16, 5000), 5000u);   // at most the cap
  EXPECT_EQ(samples_for_target(1.0f, 0.0, 16, 5000), 5000u);       // no target: the cap
}

}  // namespace
}  // namespace exitance
