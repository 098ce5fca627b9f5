// The Vulkan kernels' per-sample strategy for --guiding auto (common/guiding_auto_strategy.h, one
// text for C++ and GLSL) from GuidingChoice::strategy_word is GuidingChoice's own: which strategy
// each sample runs and which (stream, index) its sampler uses, for many texels and samples, in the
// pilot and after a choice that guides some texels and not others.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "exitance/common/guiding_auto_strategy.h"
#include "exitance/runtime/core/guiding_choice.h"

namespace exitance {
namespace {

constexpr uint32_t kPilot = 32;
constexpr uint32_t kFrom = 8;
constexpr size_t kTexels = 4000;

// Every texel and every sample up to three pilots: the word's answers are the choice's.
void expect_words_match(const GuidingChoice& c) {
  size_t guided = 0;
  for (size_t i = 0; i < kTexels; ++i) {
    const uint32_t word = c.strategy_word(i);
    for (uint32_t s = 0; s < 3 * kPilot; ++s) {
      const bool g = c.sample_guided(i, s);
      guided += g;
      ASSERT_EQ(auto_sample_guided(word, s, kPilot), g) << "texel " << i << " sample " << s;
      ASSERT_EQ(auto_strategy_sample_index(word, s, kPilot, g), c.strategy_sample_index(i, s, g)) << i << " " << s;
      ASSERT_EQ(auto_sample_stream(uint32_t(i), g), g ? GuidingChoice::guided_stream(i) : uint64_t(i)) << i;
    }
  }
  EXPECT_GT(guided, 0u) << "some samples are guided";
}

TEST(GuidingAutoStrategy, WordsMatchTheChoiceInThePilot) {
  std::vector<uint32_t> region(kTexels);
  for (size_t i = 0; i < kTexels; ++i) region[i] = uint32_t(i % 2);
  const GuidingChoice c(region, 2, kPilot, kFrom, 11);
  expect_words_match(c);
}

// Region 0: guided samples constant, unguided ones 0 or 2 (guiding pays); region 1 the other way.
TEST(GuidingAutoStrategy, WordsMatchTheChoiceAfterIt) {
  std::vector<uint32_t> region(kTexels);
  for (size_t i = 0; i < kTexels; ++i) region[i] = uint32_t(i % 2);
  GuidingChoice c(region, 2, kPilot, kFrom, 12);
  for (size_t i = 0; i < kTexels; ++i)
    for (uint32_t s = kFrom; s < kPilot; ++s) {
      const bool g = c.sample_guided(i, s);
      const bool steady = (region[i] == 0) == g;
      c.record(i, s, g, steady ? 1.0 : double(2 * (s % 2)), 10, g ? 2 : 0);
    }
  c.decide();
  ASSERT_TRUE(c.regions()[0].guided);
  ASSERT_FALSE(c.regions()[1].guided);
  expect_words_match(c);
}

}  // namespace
}  // namespace exitance
