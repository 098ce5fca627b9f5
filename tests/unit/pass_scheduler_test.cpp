// PassScheduler's pass sizes (core/pass_scheduler.h): the ramp, the doubling ramp emitter guiding
// learns in, and EmitterGuidingCache::folds_after, the fold points both backends share.
#include <gtest/gtest.h>

#include <vector>

#include "exitance/runtime/core/emitter_guiding_cache.h"
#include "exitance/runtime/core/pass_scheduler.h"

namespace exitance {
namespace {

// The pass sizes of an untimed run of `spp` samples.
std::vector<uint32_t> pass_sizes(uint32_t spp, PassPolicy policy) {
  IntegratorSettings settings;
  settings.spp = spp;
  PassScheduler passes(settings, policy);
  std::vector<uint32_t> sizes;
  uint32_t first = 0, count = 0;
  while (passes.next_pass(first, count)) {
    EXPECT_EQ(first, passes.samples_done());
    sizes.push_back(count);
    passes.finish_pass(0);
  }
  return sizes;
}

TEST(PassScheduler, RampsOneThenFourThenSixteen) {
  PassPolicy policy;
  policy.ramp = true;
  const std::vector<uint32_t> sizes = pass_sizes(96, policy);
  std::vector<uint32_t> expected{1, 1, 1, 1};
  for (uint32_t done = 4; done < 64; done += 4) expected.push_back(4);
  expected.insert(expected.end(), {16, 16});
  EXPECT_EQ(sizes, expected);
}

TEST(PassScheduler, DoublingRampEndsAtItsBound) {
  PassPolicy policy;
  policy.ramp = true;
  policy.doubling_below = EmitterGuidingCache::kEveryLearningSamples;
  EXPECT_EQ(pass_sizes(96, policy), (std::vector<uint32_t>{1, 1, 1, 1, 4, 8, 16, 32, 16, 16}));
  // The sample cap cuts the last pass; the largest pass bounds every pass.
  EXPECT_EQ(pass_sizes(20, policy), (std::vector<uint32_t>{1, 1, 1, 1, 4, 8, 4}));
  policy.largest_pass = 6;
  EXPECT_EQ(pass_sizes(40, policy), (std::vector<uint32_t>{1, 1, 1, 1, 4, 6, 6, 6, 6, 6, 2}));
  // Below ramp_below only: past it the largest passes.
  policy.largest_pass = 0xFFFFFFFFu;
  policy.ramp_below = 64;
  EXPECT_EQ(pass_sizes(200, policy), (std::vector<uint32_t>{1, 1, 1, 1, 4, 8, 16, 32, 136}));
}

TEST(PassScheduler, EmitterFoldsAtTheLearningPointsThenEveryPass) {
  std::vector<uint32_t> folds;
  for (uint32_t samples = 1; samples <= 70; ++samples)
    if (EmitterGuidingCache::folds_after(samples)) folds.push_back(samples);
  EXPECT_EQ(folds, (std::vector<uint32_t>{1, 2, 3, 4, 8, 16, 32, 64, 65, 66, 67, 68, 69, 70}));
}

}  // namespace
}  // namespace exitance
