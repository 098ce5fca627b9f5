#version 460
#extension GL_GOOGLE_include_directive : require
// Grid guiding's fold between learning passes on the device (issue 35, item 1; vulkan/guide_buffer.h):
// per record, its bins' back sums folded into the learned radiance and weight and cleared, and, where
// a bin learned anything, the record's CDF and front words rebuilt: common/guide_fold.h, the code of
// GridGuidingCache::swap. One invocation per record, its bins in order, so the result does not depend
// on the dispatch and the next pass reads the new table with no host round trip.
layout(local_size_x = 64) in;
#include "exitance/common/gpu_layout.h"

layout(std430, set = 0, binding = 0) buffer Guide { uint guide_words[]; };
float guide_cdf_at(uint cdf, uint i) { return uintBitsToFloat(guide_words[cdf + i]); }  // guided_direction.h's reader
#include "exitance/common/guided_direction.h"
layout(push_constant) uniform Push {
  uint first;   // this dispatch's first record
  float mix;    // the guided share of a learned record (GridGuidingConfig::mix)
} push;

uint learned_word(uint record, uint bin) { return guide_words[kGuideLearnedOffset] + (record * kGuideBins + bin) * kGuideLearnedWords; }
float guide_fold_radiance(uint record, uint bin) { return uintBitsToFloat(guide_words[learned_word(record, bin)]); }
float guide_fold_weight(uint record, uint bin) { return uintBitsToFloat(guide_words[learned_word(record, bin) + 1u]); }
void guide_fold_write_cdf(uint record, uint i, float value) {
  guide_words[guide_words[kGuideCdfOffset] + record * (kGuideBins + 1u) + i] = floatBitsToUint(value);
}
#include "exitance/common/guide_fold.h"

void main() {
  uint record = push.first + gl_GlobalInvocationID.x;
  if (record >= guide_words[kGuideRecordCount]) return;
  double units = packDouble2x32(uvec2(guide_words[kGuideFixedUnits], guide_words[kGuideFixedUnits + 1u]));
  uint back = guide_words[kGuideBackOffset] + record * kGuideBins * kGuideBackWords;
  bool changed = false;
  for (uint b = 0u; b < kGuideBins; ++b) {
    uint at = back + b * kGuideBackWords;
    uint count = guide_words[at + 2u];
    uint64_t sum = uint64_t(guide_words[at]) | (uint64_t(guide_words[at + 1u]) << 32);
    guide_words[at] = 0u;
    guide_words[at + 1u] = 0u;
    guide_words[at + 2u] = 0u;
    uint learned = learned_word(record, b);
    float radiance = uintBitsToFloat(guide_words[learned]);
    float weight = uintBitsToFloat(guide_words[learned + 1u]);
    if (guide_fold_bin(radiance, weight, sum, count, units)) changed = true;
    guide_words[learned] = floatBitsToUint(radiance);
    guide_words[learned + 1u] = floatBitsToUint(weight);
  }
  if (!changed) return;
  GuideFoldFront front = guide_fold_rebuild(record, push.mix);
  uint f = guide_words[kGuideFrontOffset] + record * kGuideFrontWords;
  guide_words[f] = floatBitsToUint(front.guided_probability);
  guide_words[f + 1u] = floatBitsToUint(front.expected_cosine);
}
