// --guiding auto's decision (core/guiding_choice.h) on synthetic pilot samples of known variance and
// cost: it keeps the strategy with the lower variance x counted cost, deterministically, and its
// pilot gives every texel one guided and one unguided half, guided first for about half the texels.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "exitance/runtime/core/guiding_choice.h"

namespace exitance {
namespace {

constexpr uint32_t kPilot = 64, kFrom = 16;
constexpr size_t kTexels = 64;
constexpr double kGuidedCost = 10 + 8 * kGuidedVertexCostInRays;

// Pilot samples for `regions` regions of kTexels / regions texels each: every sample drawn with mean
// 1 and the deviation of its strategy; guided samples cost 10 rays and 8 guided vertices (kGuidedCost
// in rays: 15.2 at kGuidedVertexCostInRays = 0.65), unguided ones 10 rays.
GuidingChoice pilot(const std::vector<double>& guided_deviation, double unguided_deviation, uint64_t seed) {
  const uint32_t regions = uint32_t(guided_deviation.size());
  std::vector<uint32_t> region(kTexels);
  for (size_t i = 0; i < kTexels; ++i) region[i] = uint32_t(i * regions / kTexels);
  GuidingChoice choice(region, regions, kPilot, kFrom, seed, 1.0);  // every texel measures
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (size_t i = 0; i < kTexels; ++i)
    for (uint32_t s = 0; s < kPilot; ++s) {
      const bool guided = choice.sample_guided(i, s);
      const double deviation = guided ? guided_deviation[region[i]] : unguided_deviation;
      choice.record(i, s, guided, 1.0 + deviation * normal(rng), 10, guided ? 8 : 0);
    }
  choice.decide();
  return choice;
}

// Guided at 1/4 the variance for 1.5x the cost pays (ratio ~2.6), at 4x or 1/25 the variance the
// evidence is overwhelming too (z far beyond kChoiceZ); at 0.9x the variance (ratio ~0.73, z ~ -3)
// the region's own evidence is weak and it follows the scene, where guiding does not pay. Each region has 16 texels x ~24 samples per strategy: a variance estimate's
// relative error is ~7 %, the ratio's ~10 %, far from the margins.
TEST(GuidingChoice, KeepsTheStrategyWithLowerVarianceTimesCost) {
  const GuidingChoice c = pilot({0.05, 0.095, 0.2, 0.02}, 0.1, 3);
  ASSERT_TRUE(c.decided());
  ASSERT_EQ(c.regions().size(), 4u);
  EXPECT_TRUE(c.regions()[0].guided);
  EXPECT_FALSE(c.regions()[1].guided);
  EXPECT_FALSE(c.regions()[2].guided);
  EXPECT_TRUE(c.regions()[3].guided);
  EXPECT_EQ(c.regions_guided(), 2u);
  EXPECT_EQ(c.regions()[0].basis, ChoiceBasis::Region);
  EXPECT_EQ(c.regions()[2].basis, ChoiceBasis::Region);
  EXPECT_EQ(c.regions()[3].basis, ChoiceBasis::Region);
  EXPECT_LT(c.scene().z(), -kChoiceZ);
  EXPECT_EQ(c.texels_guided(), kTexels / 2);
  for (const RegionChoice& r : c.regions()) {
    EXPECT_EQ(r.texels_measured, 16u);
    EXPECT_NEAR(r.cost_per_sample[0], 10.0, 1e-9);
    EXPECT_NEAR(r.cost_per_sample[1], kGuidedCost, 1e-9);
  }
  // A ratio of two variance estimates of ~16 x 23 degrees of freedom each: relative SE sqrt(2/368 + 2/368).
  const double relative_se = std::sqrt(4.0 / 368.0);
  const double expected0 = 4.0 * 10 / kGuidedCost, expected1 = 1.0 / 0.9025 * 10 / kGuidedCost;
  EXPECT_NEAR(c.regions()[0].efficiency_ratio, expected0, 5 * relative_se * expected0);
  EXPECT_NEAR(c.regions()[1].efficiency_ratio, expected1, 5 * relative_se * expected1);
  // After the choice every sample of a texel follows its region.
  for (uint32_t s = 64; s < 80; ++s) {
    EXPECT_TRUE(c.sample_guided(0, s));
    EXPECT_FALSE(c.sample_guided(20, s));
  }
}

// Seven regions where guiding clearly pays and one where it is even (ratio ~0.99): the even one has
// no evidence of its own and follows the scene's verdict.
TEST(GuidingChoice, RegionsWithoutEvidenceFollowTheScene) {
  const GuidingChoice c = pilot({0.05, 0.05, 0.05, 0.05, 0.05, 0.05, 0.05, 0.1 * std::sqrt(10.0 / kGuidedCost)}, 0.1, 7);
  EXPECT_GT(c.scene().z(), kChoiceZ);
  for (size_t r = 0; r < 7; ++r) EXPECT_EQ(c.regions()[r].basis, ChoiceBasis::Region) << r;
  EXPECT_LT(std::fabs(c.regions()[7].z), kChoiceZ);
  EXPECT_EQ(c.regions()[7].basis, ChoiceBasis::Scene);
  EXPECT_EQ(c.regions_guided(), 8u);
}

TEST(GuidingChoice, DeterministicGivenTheSums) {
  const GuidingChoice a = pilot({0.05, 0.1, 0.2}, 0.1, 11), b = pilot({0.05, 0.1, 0.2}, 0.1, 11);
  for (size_t r = 0; r < a.regions().size(); ++r) {
    EXPECT_EQ(a.regions()[r].guided, b.regions()[r].guided);
    EXPECT_EQ(a.regions()[r].efficiency_ratio, b.regions()[r].efficiency_ratio);  // bitwise
  }
}

// Every texel's pilot: one aligned half guided, the other not (stratified Sobol blocks); the guided
// half first for about half the texels (binomial, 5 standard deviations), depending on the seed.
// Light subpaths' pilot (set_candidate_half_second): every measuring texel's candidate half comes
// second, so abandoning in the first half leaves an unguided bake whose samples keep their indices.
TEST(GuidingChoice, CandidateHalfSecondAndAbandoned) {
  const uint32_t pilot = 16;
  std::vector<uint32_t> region(64, 0);
  GuidingChoice choice(region, 1, pilot, 0, 3, 1.0);  // every texel measures
  choice.set_candidate_half_second();
  for (size_t i = 0; i < region.size(); ++i)
    for (uint32_t s = 0; s < pilot; ++s) EXPECT_EQ(choice.sample_guided(i, s), s >= pilot / 2) << i << " " << s;
  choice.abandon();
  EXPECT_TRUE(choice.decided());
  EXPECT_TRUE(choice.abandoned());
  EXPECT_EQ(choice.texels_guided(), 0u);
  for (size_t i = 0; i < region.size(); ++i)
    for (uint32_t s = 0; s < 4 * pilot; ++s) {
      EXPECT_FALSE(choice.sample_guided(i, s));
      EXPECT_EQ(choice.strategy_sample_index(i, s, false), s) << "the unguided sequence, unbroken";
    }
  // Without the candidate half second, a candidate sample may already be in: not abandoned.
  GuidingChoice coin(region, 1, pilot, 0, 3, 1.0);
  EXPECT_THROW(coin.abandon(), std::logic_error);
}

TEST(GuidingChoice, PilotHalvesPerTexel) {
  constexpr size_t kMany = 1000;
  GuidingChoice c(std::vector<uint32_t>(kMany, 0), 1, kPilot, kFrom, 5, 1.0);
  GuidingChoice other(std::vector<uint32_t>(kMany, 0), 1, kPilot, kFrom, 6, 1.0);
  size_t guided_first = 0, differ = 0;
  for (size_t i = 0; i < kMany; ++i) {
    uint32_t guided = 0;
    for (uint32_t s = 0; s < kPilot; ++s) {
      guided += c.sample_guided(i, s);
      EXPECT_EQ(c.sample_guided(i, s), c.sample_guided(i, s < kPilot / 2 ? 0 : kPilot / 2)) << i << " " << s;
    }
    EXPECT_EQ(guided, kPilot / 2);
    guided_first += c.sample_guided(i, 0);
    differ += c.sample_guided(i, 0) != other.sample_guided(i, 0);
  }
  const double n = kMany;
  EXPECT_NEAR(double(guided_first), n / 2, 5 * std::sqrt(n / 4));
  EXPECT_NEAR(double(differ), n / 2, 5 * std::sqrt(n / 4));
  EXPECT_THROW(GuidingChoice({0}, 1, 24, 6, 1), std::invalid_argument);  // not a power of two
}

// With the default share, about a quarter of the texels measure (binomial, 5 standard deviations);
// the others take no guided sample in the pilot, and each strategy's samples are numbered from 0 on
// its own sequence without gaps.
TEST(GuidingChoice, AQuarterOfTheTexelsMeasure) {
  constexpr size_t kMany = 4000;
  GuidingChoice c(std::vector<uint32_t>(kMany, 0), 1, kPilot, kFrom, 9);
  size_t measuring = 0;
  for (size_t i = 0; i < kMany; ++i) {
    measuring += c.measuring(i);
    uint32_t next[2] = {0, 0};
    for (uint32_t s = 0; s < kPilot; ++s) {
      const bool g = c.sample_guided(i, s);
      if (!c.measuring(i)) EXPECT_FALSE(g);
      EXPECT_EQ(c.strategy_sample_index(i, s, g), next[g]++) << i << " " << s;
    }
    // After the pilot either strategy continues where its sequence stopped.
    EXPECT_EQ(c.strategy_sample_index(i, kPilot, false), next[0]);
    EXPECT_EQ(c.strategy_sample_index(i, kPilot, true), next[1]);
  }
  const double n = kMany, p = kPilotMeasuringShare;
  EXPECT_NEAR(double(measuring), n * p, 5 * std::sqrt(n * p * (1 - p)));
}

// Samples outside [statistics_from, pilot) are not counted; a region with nothing measured, or
// with equal efficiency, stays unguided.
TEST(GuidingChoice, CountsOnlyThePilotWindowAndDefaultsToUnguided) {
  GuidingChoice c({0, 0, 1}, 2, 8, 2, 1, 1.0);
  for (uint32_t s = 0; s < 12; ++s) {
    c.record(0, s, false, double(s % 3), 4, 0);
    c.record(0, s, true, double(s % 3), 4, 0);
  }
  EXPECT_EQ(c.sums(0, false).samples, 6u);
  EXPECT_EQ(c.sums(0, true).samples, 6u);
  c.decide();
  EXPECT_NEAR(c.regions()[0].efficiency_ratio, 1.0, 1e-12);  // same values, same cost: a tie
  EXPECT_FALSE(c.regions()[0].guided);
  EXPECT_EQ(c.regions()[0].basis, ChoiceBasis::Default);
  EXPECT_EQ(c.regions()[1].texels_measured, 0u);
  EXPECT_FALSE(c.regions()[1].guided);
  EXPECT_THROW(GuidingChoice({0, 3}, 2, 8, 2, 1), std::invalid_argument);
}

}  // namespace
}  // namespace exitance
