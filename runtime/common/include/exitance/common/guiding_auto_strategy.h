// --guiding auto's per-sample strategy (core/guiding_choice.h) from one word per texel, for the
// Vulkan backend's kernels: which strategy a texel's sample `sample_index` runs, and which (stream, index)
// its sampler uses. The host packs the word from GuidingChoice (measuring, its coin, and after the
// choice the texel's leave-one-out verdict); these functions are GuidingChoice::sample_guided,
// strategy_sample_index and guided_stream on that word (tests/unit/guiding_auto_strategy_test.cpp
// checks them against GuidingChoice for many texels and samples), one text for C++ and GLSL.
#ifndef EXITANCE_COMMON_GUIDING_AUTO_STRATEGY_H
#define EXITANCE_COMMON_GUIDING_AUTO_STRATEGY_H
#include "exitance/common/dialect.h"
EXITANCE_NAMESPACE_BEGIN

const uint kAutoMeasuring = 1u;    // the texel measures both strategies in the pilot
const uint kAutoGuidedFirst = 2u;  // its pilot's first half is guided (the hashed coin)
const uint kAutoDecided = 4u;      // the choice is made: kAutoGuided is the texel's strategy from here
const uint kAutoGuided = 8u;
// GuidingChoice::guided_stream's salt: a texel's guided samples on a stream of their own.
const uint64_t kAutoGuidedStreamSalt = 0xA5E1D6C3B2F40000ul;

// GuidingChoice::sample_guided.
EXITANCE_FN bool auto_sample_guided(uint word, uint sample_index, uint pilot) {
  if ((word & kAutoDecided) != 0u) return (word & kAutoGuided) != 0u;
  if ((word & kAutoMeasuring) == 0u) return false;
  return (sample_index < pilot / 2u) == ((word & kAutoGuidedFirst) != 0u);
}

// GuidingChoice::strategy_sample_index: the sample's index within its strategy's own sequence.
EXITANCE_FN uint auto_strategy_sample_index(uint word, uint sample_index, uint pilot, bool guided) {
  if ((word & kAutoMeasuring) == 0u) return guided ? sample_index - min(sample_index, pilot) : sample_index;  // an all-unguided pilot
  return sample_index < pilot ? sample_index % (pilot / 2u) : sample_index - pilot / 2u;
}

// The sampler's stream of a texel's sample: GuidingChoice::guided_stream for guided ones.
EXITANCE_FN uint64_t auto_sample_stream(uint texel, bool guided) {
  return guided ? (uint64_t(texel) ^ kAutoGuidedStreamSalt) : uint64_t(texel);
}

EXITANCE_NAMESPACE_END
#endif
