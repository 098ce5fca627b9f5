// The per-bounce mode's time budget (core/per_bounce_bake.h, core/partial_layer_pass.h): the last
// layer pass that does not fit whole gives one more sample to a hashed part of the texels. Driven
// by a virtual clock that a stand-in estimator advances by a fixed cost per texel sample, so the
// cuts do not depend on the machine: the schedule is checked exactly, the budget against the
// spread of the partial pass's hashed texel count.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "exitance/common/rng.h"
#include "exitance/runtime/core/partial_layer_pass.h"
#include "exitance/runtime/core/per_bounce_bake.h"

namespace exitance {
namespace {

TEST(PartialLayerPass, CutKeepsTheWholeSamplesThatFitThenAFraction) {
  LayerPassCut c = cut_layer_pass(2.5, 1.0, 4);
  EXPECT_TRUE(c.cut);
  EXPECT_EQ(c.whole, 2u);
  EXPECT_DOUBLE_EQ(c.fraction, 0.5);
  c = cut_layer_pass(10.0, 1.0, 4);  // fits: uncut
  EXPECT_FALSE(c.cut);
  EXPECT_EQ(c.whole, 4u);
  EXPECT_EQ(c.fraction, 0.0);
  c = cut_layer_pass(4.0, 1.0, 4);  // exactly fits
  EXPECT_FALSE(c.cut);
  EXPECT_EQ(c.whole, 4u);
  c = cut_layer_pass(10.0, 0.0, 4);  // cost not measured yet: uncut
  EXPECT_FALSE(c.cut);
  EXPECT_EQ(c.whole, 4u);
  c = cut_layer_pass(-1.0, 1.0, 4);  // past the budget already
  EXPECT_TRUE(c.cut);
  EXPECT_EQ(c.whole, 0u);
  EXPECT_EQ(c.fraction, 0.0);
  c = cut_layer_pass(0.5 * kSmallestPartialFraction, 1.0, 4);  // too few texels to be worth a pass
  EXPECT_TRUE(c.cut);
  EXPECT_EQ(c.whole, 0u);
  EXPECT_EQ(c.fraction, 0.0);
}

// The chosen texels are a Bernoulli(fraction) choice per texel: their count, over the whole list and
// over every tenth of it (spread over the atlas), stays within 5 binomial standard deviations.
TEST(PartialLayerPass, ChosenTexelsAreTheFractionSpreadOverTheList) {
  constexpr size_t kTexels = 200000, kBlocks = 10;
  constexpr double kFraction = 0.3;
  const PartialPassTexels chosen(kFraction, 7, 2, 5);
  const std::vector<uint32_t> all = chosen.in_range(0, kTexels);
  const double sd = std::sqrt(double(kTexels) * kFraction * (1 - kFraction));
  EXPECT_NEAR(double(all.size()), kFraction * kTexels, 5 * sd);
  const size_t block = kTexels / kBlocks;
  const double block_sd = std::sqrt(double(block) * kFraction * (1 - kFraction));
  for (size_t b = 0; b < kBlocks; ++b) {
    const std::vector<uint32_t> part = chosen.in_range(b * block, (b + 1) * block);
    EXPECT_NEAR(double(part.size()), kFraction * double(block), 5 * block_sd) << "block " << b;
    for (uint32_t i : part) ASSERT_TRUE(chosen.covers(i));
  }
  for (size_t j = 1; j < all.size(); ++j) ASSERT_LT(all[j - 1], all[j]);
  // Another sample (or layer) chooses other texels: about fraction^2 of them in both.
  const PartialPassTexels other(kFraction, 7, 2, 6);
  size_t both = 0;
  for (uint32_t i : all) both += other.covers(i) ? 1 : 0;
  const double p = kFraction * kFraction;
  EXPECT_NEAR(double(both), p * kTexels, 5 * std::sqrt(double(kTexels) * p * (1 - p)));
  EXPECT_EQ(PartialPassTexels(0.0, 7, 2, 5).in_range(0, kTexels).size(), 0u);
  EXPECT_EQ(PartialPassTexels(1.0, 7, 2, 5).in_range(0, kTexels).size(), kTexels);
}

// A stand-in layer estimator: sample s of layer k at texel i is a fixed value (a hash), each texel
// sample costs `seconds_per_texel_sample[k]` (times `slowdown` from sample index `slow_from` on) on
// the virtual clock. It records every texel's samples per layer, in the order they came.
class RecordingEstimator final : public BounceLayerEstimator {
 public:
  RecordingEstimator(size_t texels, std::vector<double> seconds_per_texel_sample, double& clock)
      : texels_(texels), cost_(std::move(seconds_per_texel_sample)), clock_(clock) {}

  static double value(int layer, size_t texel, uint32_t sample) {
    const uint64_t h = splitmix64((uint64_t(uint32_t(layer)) << 48) ^ (uint64_t(texel) << 20) ^ sample);
    return 0.5 + double(h >> 11) * 0x1.0p-53;  // in [0.5, 1.5)
  }

  void estimate(const BounceLayerPass& pass, const std::vector<BounceLayerCache>&, const std::vector<uint64_t>&) override {
    if (samples_.size() <= size_t(pass.layer)) samples_.resize(size_t(pass.layer) + 1);
    std::vector<std::vector<uint32_t>>& layer = samples_[size_t(pass.layer)];
    layer.resize(texels_);
    std::vector<uint32_t> texels;
    if (pass.texels) {
      texels = *pass.texels;
      ++partial_passes_;
    } else {
      for (size_t i = pass.begin; i < pass.end; ++i) texels.push_back(uint32_t(i));
    }
    for (uint32_t i : texels) {
      for (uint32_t s = pass.first_sample; s < pass.first_sample + pass.samples; ++s) {
        layer[i].push_back(s);
        const double v = value(pass.layer, i, s);
        for (int c = 0; c < 3; ++c) pass.sum[i * 3 + size_t(c)] += v, pass.sum_squared[i * 3 + size_t(c)] += v * v;
        clock_ += cost_[size_t(pass.layer)] * (s >= slow_from ? slowdown : 1.0);
        ++rays_;
      }
    }
  }
  BounceGatherCounts counts() const override {
    BounceGatherCounts c;
    c.rays = rays_;
    return c;
  }

  // Per layer, per texel, the sample indices it took in order.
  const std::vector<std::vector<std::vector<uint32_t>>>& samples() const { return samples_; }
  int partial_passes() const { return partial_passes_; }

  uint32_t slow_from = 0xFFFFFFFFu;
  double slowdown = 1;

 private:
  size_t texels_;
  std::vector<double> cost_;
  double& clock_;
  std::vector<std::vector<std::vector<uint32_t>>> samples_;
  uint64_t rays_ = 0;
  int partial_passes_ = 0;
};

TexelGBuffer texels_without_atlas(size_t n) {
  TexelGBuffer g;
  g.texels.resize(n);
  for (size_t i = 0; i < n; ++i) {
    g.texels[i].position = {float(i), 0, 0};
    g.texels[i].geometric_normal = g.texels[i].shading_normal = {0, 1, 0};
    g.texels[i].albedo = {0.5f, 0.5f, 0.5f};
    g.texels[i].world_texel_size = 1;
  }
  return g;
}

IntegratorSettings timed_settings(double budget, const double& clock) {
  IntegratorSettings s;
  s.integrator = IntegratorMode::Bounces;
  s.spp = 0;
  s.time_budget_seconds = budget;
  s.max_bounces = 2;  // B_0, B_1, B_2, all started in the first pass
  s.seed = 11;
  s.budget_clock = [&clock] { return clock; };
  return s;
}

// Every sample index of every (layer, texel) comes once and in order from 0; the estimate's layer
// means, texel counts and variances are those of exactly the recorded samples.
void expect_estimate_matches_recorded_samples(const LightmapEstimate& e, const RecordingEstimator& rec) {
  const size_t n = e.texels.size();
  const int layers = e.recorded_bounces;
  ASSERT_EQ(rec.samples().size(), size_t(layers));
  for (int k = 0; k < layers; ++k) {
    const std::vector<std::vector<uint32_t>>& layer = rec.samples()[size_t(k)];
    uint64_t with_one_more = 0;
    for (size_t i = 0; i < n; ++i) {
      const std::vector<uint32_t>& taken = layer[i];
      for (size_t j = 0; j < taken.size(); ++j) ASSERT_EQ(taken[j], j) << "layer " << k << " texel " << i;
      const uint32_t count = uint32_t(taken.size());
      ASSERT_TRUE(count == e.bounce_statistics.samples[size_t(k)] || count == e.bounce_statistics.samples[size_t(k)] + 1)
          << "layer " << k << " texel " << i << ": " << count << " samples";
      with_one_more += count > e.bounce_statistics.samples[size_t(k)] ? 1 : 0;
      if (k == 0) ASSERT_EQ(e.texels[i].samples, count) << "texel " << i;
      double sum = 0;
      for (uint32_t s : taken) sum += RecordingEstimator::value(k, i, s);
      const double mean = sum / count;
      ASSERT_NEAR(e.mean_bounce(k, i)[1], mean, 1e-6 * mean) << "layer " << k << " texel " << i;
    }
    EXPECT_EQ(e.bounce_statistics.texels_with_one_more[size_t(k)], with_one_more) << "layer " << k;
  }
  // The total's variance: the layers' sample variances over each texel's own counts, summed.
  for (size_t i = 0; i < n; ++i) {
    double variance = 0;
    for (int k = 0; k < layers; ++k) {
      const std::vector<uint32_t>& taken = rec.samples()[size_t(k)][i];
      const double m = double(taken.size());
      double sum = 0, sum_squared = 0;
      for (uint32_t s : taken) {
        const double v = RecordingEstimator::value(k, i, s);
        sum += v, sum_squared += v * v;
      }
      variance += (sum_squared - sum * sum / m) / (m - 1) / m;
    }
    ASSERT_NEAR(e.variance_of_mean(i)[1], variance, 1e-4 * variance) << "texel " << i;
  }
}

// 1000 texels; a sample of every texel costs 1 s in B_0 and 2 s in B_1 and B_2: a pass of one
// sample is 5 s. With 12.3 s, two passes run whole (10 s), B_0's third sample fits (11 s), and B_1's
// does not: 0.65 of its texels get it, hashed, and the bake ends there.
TEST(PerBounceBudget, LastPassGivesOneMoreSampleToAPartOfTheTexels) {
  constexpr size_t kTexels = 1000;
  constexpr double kBudget = 12.3, kCost1 = 2e-3;
  double clock = 0;
  const TexelGBuffer g = texels_without_atlas(kTexels);
  RecordingEstimator rec(kTexels, {1e-3, kCost1, kCost1}, clock);
  const LightmapEstimate e = bake_per_bounce(g, timed_settings(kBudget, clock), rec);
  const BounceGatherStatistics& b = e.bounce_statistics;
  std::printf("[budget] virtual %.4f s of %.4f; samples %u %u %u, one more in B_1: %llu texels\n", clock, kBudget,
              b.samples[0], b.samples[1], b.samples[2], (unsigned long long)b.texels_with_one_more[1]);
  ASSERT_EQ(e.recorded_bounces, 3);
  EXPECT_EQ(b.samples, (std::vector<uint32_t>{3, 2, 2}));
  EXPECT_EQ(rec.partial_passes(), 1);
  EXPECT_EQ(b.texels_with_one_more[0], 0u);
  EXPECT_EQ(b.texels_with_one_more[2], 0u);
  // The partial pass's texel count is Binomial(1000, 0.65): the clock ends within 5 of its standard
  // deviations (times a B_1 texel sample's cost) of the budget.
  const double sd = std::sqrt(kTexels * 0.65 * 0.35);
  EXPECT_NEAR(double(b.texels_with_one_more[1]), 0.65 * kTexels, 5 * sd);
  EXPECT_NEAR(clock, kBudget, 5 * sd * kCost1);
  expect_estimate_matches_recorded_samples(e, rec);
}

// Without the partial pass the same budget would have stopped at 11 s; with a budget that ends
// exactly on a pass nothing partial runs.
TEST(PerBounceBudget, BudgetOnAPassBoundaryRunsNoPartialPass) {
  constexpr size_t kTexels = 1000;
  double clock = 0;
  const TexelGBuffer g = texels_without_atlas(kTexels);
  RecordingEstimator rec(kTexels, {1e-3, 2e-3, 2e-3}, clock);
  const LightmapEstimate e = bake_per_bounce(g, timed_settings(10.0, clock), rec);
  EXPECT_EQ(e.bounce_statistics.samples, (std::vector<uint32_t>{2, 2, 2}));
  EXPECT_EQ(rec.partial_passes(), 0);
  EXPECT_NEAR(clock, 10.0, 1e-9);
  expect_estimate_matches_recorded_samples(e, rec);
}

// The cost grows by half from sample 4 on (a machine that got busier): the ramp's pass of 3
// samples no longer fits, and the layer it runs out in takes whole samples and then a partial one
// in the same step; the indices stay consecutive per texel and the estimate is their mean.
TEST(PerBounceBudget, WholeSamplesAndThenAPartialOneInTheSameLayer) {
  constexpr size_t kTexels = 1000;
  double clock = 0;
  const TexelGBuffer g = texels_without_atlas(kTexels);
  RecordingEstimator rec(kTexels, {1e-3, 2e-3, 2e-3}, clock);
  rec.slow_from = 4, rec.slowdown = 1.5;
  const LightmapEstimate e = bake_per_bounce(g, timed_settings(38.0, clock), rec);
  const BounceGatherStatistics& b = e.bounce_statistics;
  std::printf("[budget] slowed: virtual %.4f s of 38; samples %u %u %u, one more: %llu %llu %llu\n", clock, b.samples[0],
              b.samples[1], b.samples[2], (unsigned long long)b.texels_with_one_more[0],
              (unsigned long long)b.texels_with_one_more[1], (unsigned long long)b.texels_with_one_more[2]);
  // Passes 1-4 whole (20 s); pass 5 asks for 3 samples: B_0 and B_1 take them at 1.5x (24.5 s, 33.5 s),
  // B_2's 4.5 s left at its measured 2 s per sample hold 2 whole samples and a quarter.
  EXPECT_EQ(b.samples, (std::vector<uint32_t>{7, 7, 6}));
  EXPECT_EQ(rec.partial_passes(), 1);
  const double sd = std::sqrt(kTexels * 0.25 * 0.75);
  EXPECT_NEAR(double(b.texels_with_one_more[2]), 0.25 * kTexels, 5 * sd);
  expect_estimate_matches_recorded_samples(e, rec);
}

}  // namespace
}  // namespace exitance
