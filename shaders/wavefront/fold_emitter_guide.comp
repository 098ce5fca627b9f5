#version 460
#extension GL_GOOGLE_include_directive : require
// Emitter guiding's fold between passes on the device (issue 35; vulkan/emitter_guide_buffer.h):
// per record, its patches' and punctual lights' back sums folded into the learned section and
// cleared, and, where any learned something, the record's CDFs and guided probabilities rebuilt:
// common/emitter_guide_fold.h, the code of EmitterGuidingCache::swap. Each record then counts
// itself in the section's kEmitterGuideSampling word if it samples what it learned (the host reads
// that one word to stop the cache, as end_pass does). One invocation per record, its rows in order,
// so the result does not depend on the dispatch, and the next pass reads the new tables with no
// host round trip.
layout(local_size_x = 64) in;
#include "exitance/common/gpu_layout.h"

layout(std430, set = 0, binding = 0) buffer Guide { uint guide_words[]; };
layout(push_constant) uniform Push {
  uint first;    // this dispatch's first record
  uint section;  // the emitter section's first word (GpuParams::emitter_guide)
} push;

uint header(uint word) { return guide_words[push.section + word]; }
uint patch_count() { return header(kEmitterGuidePatches); }
uint punctual_count() { return header(kEmitterGuidePunctual); }

double word_double(uint at) { return packDouble2x32(uvec2(guide_words[at], guide_words[at + 1u])); }
void write_double(uint at, double value) {
  uvec2 w = unpackDouble2x32(value);
  guide_words[at] = w.x;
  guide_words[at + 1u] = w.y;
}
uint learned_word(uint record, uint k) { return header(kEmitterGuideLearned) + (record * patch_count() + k) * kEmitterGuideLearnedWords; }
uint punctual_learned_word(uint record, uint i) {
  return header(kEmitterGuidePunctualLearned) + (record * punctual_count() + i) * kEmitterGuidePunctualLearnedWords;
}
uint cdf_word(uint record, uint table, uint i) {
  return table == 0u ? header(kEmitterGuideCdf) + record * (patch_count() + 1u) + i
                     : header(kEmitterGuidePunctualCdf) + record * (punctual_count() + 1u) + i;
}

// common/emitter_guide_fold.h's accessors (table 0: patches, 1: punctual lights).
double emitter_fold_learned(uint record, uint table, uint k) {
  return word_double(table == 0u ? learned_word(record, k) : punctual_learned_word(record, k));
}
uint emitter_fold_samples(uint record, uint k) { return guide_words[learned_word(record, k) + 2u]; }
float emitter_fold_default(uint record, uint table, uint k) {
  return uintBitsToFloat(guide_words[header(table == 0u ? kEmitterGuideDefault : kEmitterGuidePunctualDefault) + k]);
}
uint emitter_fold_cluster_first(uint record, uint c) { return guide_words[header(kEmitterGuideClusterFirst) + c]; }
float emitter_fold_cdf(uint record, uint table, uint i) { return uintBitsToFloat(guide_words[cdf_word(record, table, i)]); }
void emitter_fold_write_cdf(uint record, uint table, uint i, float value) { guide_words[cdf_word(record, table, i)] = floatBitsToUint(value); }
#include "exitance/common/emitter_guide_fold.h"

void main() {
  uint record = push.first + gl_GlobalInvocationID.x;
  if (record >= header(kEmitterGuideRecords)) return;
  double units = packDouble2x32(uvec2(header(kEmitterGuideFixedUnits), header(kEmitterGuideFixedUnits + 1u)));
  uint patches = patch_count();
  uint punctual = punctual_count();
  bool changed = false;
  uint back = header(kEmitterGuideBack) + record * patches * kGuideBackWords;
  for (uint k = 0u; k < patches; ++k) {
    uint at = back + k * kGuideBackWords;
    uint count = guide_words[at + 2u];
    if (count == 0u) continue;
    uint64_t sum = uint64_t(guide_words[at]) | (uint64_t(guide_words[at + 1u]) << 32);
    guide_words[at] = 0u;
    guide_words[at + 1u] = 0u;
    guide_words[at + 2u] = 0u;
    uint learned = learned_word(record, k);
    double value = word_double(learned);
    emitter_fold_add(value, sum, units);
    write_double(learned, value);
    guide_words[learned + 2u] += count;
    changed = true;
  }
  uint punctual_back = header(kEmitterGuidePunctualBack) + record * punctual * kEmitterGuidePunctualBackWords;
  for (uint i = 0u; i < punctual; ++i) {
    uint at = punctual_back + i * kEmitterGuidePunctualBackWords;
    uint64_t sum = uint64_t(guide_words[at]) | (uint64_t(guide_words[at + 1u]) << 32);
    if (sum == 0ul) continue;
    guide_words[at] = 0u;
    guide_words[at + 1u] = 0u;
    uint learned = punctual_learned_word(record, i);
    double value = word_double(learned);
    emitter_fold_add(value, sum, units);
    write_double(learned, value);
    changed = true;
  }
  uint front = header(kEmitterGuideFront) + record * kEmitterGuideFrontWords;
  if (changed) {
    float mix = uintBitsToFloat(header(kEmitterGuideMix));
    if (punctual > 0u) guide_words[front + 1u] = floatBitsToUint(emitter_fold_rebuild_punctual(record, punctual, mix));
    if (patches > 0u)
      guide_words[front] = floatBitsToUint(emitter_fold_rebuild_patches(record, patches, header(kEmitterGuideClusters), mix));
  }
  if (uintBitsToFloat(guide_words[front]) > 0.0 || uintBitsToFloat(guide_words[front + 1u]) > 0.0)
    atomicAdd(guide_words[push.section + kEmitterGuideSampling], 1u);
}
