#version 460
#extension GL_GOOGLE_include_directive : require
// Stage "accumulate": per texel of the batch, adds each sample's total (sum of its bounce slots),
// its square, its bounce layers and (directional batches) its L1 to double-precision sums, in sample
// order (one writer per texel). A per-bounce layer pass also counts its back-face flags; a --guiding
// auto pilot pass adds each sample's luminance moments and costs to its strategy's sums (gpu_layout.h).
layout(local_size_x = 64) in;
#include "../include/kernel_prelude.glsl"

// GuidingChoice::record on the device: texel sample `sample_index` (of strategy `guided`) with total E/pi
// `total`, counted at work item w, into the texel's strategy sums in the guide buffer's auto section.
void record_auto_sample(uint texel, uint sample_index, uint w, vec3 total) {
  uint pilot = guide_words[kGuideAutoPilot];
  if (sample_index < guide_words[kGuideAutoStatisticsFrom] || sample_index >= pilot) return;
  bool guided = auto_sample_guided(auto_texel_word(texel), sample_index, pilot);
  uint s = guide_words[kGuideAutoSums] / 2u + (texel * 2u + (guided ? 1u : 0u)) * kAutoSumDoubles;
  double y = double(luminance(total)), y2 = y * y;
  uint c = auto_cost_index(w);
  acc_probe_sh[s] += 1.0lf;
  acc_probe_sh[s + 1u] += y;
  acc_probe_sh[s + 2u] += y2;
  acc_probe_sh[s + 3u] += y2 * y;
  acc_probe_sh[s + 4u] += y2 * y2;
  acc_probe_sh[s + 5u] += double(results[c]);
  acc_probe_sh[s + 6u] += double(results[c + 1u]);
}

// The sums live in registers (local memory for the layers) through the sample loop and go back to
// the buffers once: the compiler must assume that the result and sum buffers may alias, so a
// `+=` on a buffer inside the loop was a global read and write per sample (the additions, and so
// the bits, are the same in either form: each sum still adds the samples in their order).
void main() {
  uint j = gl_GlobalInvocationID.x;
  uint n = params.batch_item_count;
  if (j >= n) return;
  uint texel = batch_items[params.batch_item_offset + j];
  uint K = params.recorded;
  bool directional = params.directional != 0u;
  uint nonfinite = 0u, samples = 0u, back_faces = 0u;
  dvec3 sum, square;
  for (uint c = 0u; c < 3u; ++c) sum[c] = acc_total[texel * 6u + c], square[c] = acc_total[texel * 6u + 3u + c];
  dvec3 layer[kMaxRecordedLayers];
  for (uint k = 0u; k < K; ++k)
    for (uint c = 0u; c < 3u; ++c) layer[k][c] = acc_bounce[(k * params.item_count_total + texel) * 3u + c];
  double sh1[9];
  if (directional)
    for (uint k = 0u; k < 9u; ++k) sh1[k] = acc_total[sh1_sum_index(texel) + k];
  for (uint s = 0u; s < params.batch_sample_count; ++s) {
    uint w = s * n + j;
    if ((params.bounce_flags & kBouncePass) != 0u && results[bounce_back_face_index(w)] > 0.0) ++back_faces;
    vec3 total = vec3(0.0);
    for (uint k = 0u; k <= K; ++k) {
      uint r = result_index(w, k);
      total += vec3(results[r], results[r + 1u], results[r + 2u]);
    }
    bool finite = !(any(isnan(total)) || any(isinf(total)));
    if (directional)
      for (uint k = 0u; k < 9u; ++k) finite = finite && !isnan(results[sh1_result_index(w) + k]) && !isinf(results[sh1_result_index(w) + k]);
    if (!finite) {
      ++nonfinite;
      // The light layers' loop below skips this sample by its NaN.
      for (uint l = 0u; l < params.light_layers; ++l) results[light_result_index(w, l)] = uintBitsToFloat(0x7FC00000u);
      continue;
    }
    if (directional)
      for (uint k = 0u; k < 9u; ++k) sh1[k] += double(results[sh1_result_index(w) + k]);
    if ((params.guiding & kGuidingAutoRecord) != 0u) record_auto_sample(texel, params.batch_sample_begin + s, w, total);
    for (uint c = 0u; c < 3u; ++c) {
      sum[c] += double(total[c]);
      square[c] += double(total[c]) * double(total[c]);
    }
    for (uint k = 0u; k < K; ++k) {
      uint r = result_index(w, k);
      for (uint c = 0u; c < 3u; ++c) layer[k][c] += double(results[r + c]);
    }
    ++samples;
  }
  for (uint c = 0u; c < 3u; ++c) acc_total[texel * 6u + c] = sum[c], acc_total[texel * 6u + 3u + c] = square[c];
  for (uint k = 0u; k < K; ++k)
    for (uint c = 0u; c < 3u; ++c) acc_bounce[(k * params.item_count_total + texel) * 3u + c] = layer[k][c];
  if (directional)
    for (uint k = 0u; k < 9u; ++k) acc_total[sh1_sum_index(texel) + k] = sh1[k];
  // Light layers (light_layers.h): after the bounce layers in the same sums, layer by layer, each
  // adding the texel's samples in order (a sample dropped above reads NaN here).
  for (uint l = 0u; l < params.light_layers; ++l) {
    uint at = ((K + l) * params.item_count_total + texel) * 3u;
    dvec3 light = dvec3(acc_bounce[at], acc_bounce[at + 1u], acc_bounce[at + 2u]);
    for (uint s = 0u; s < params.batch_sample_count; ++s) {
      uint r = light_result_index(s * n + j, l);
      vec3 v = vec3(results[r], results[r + 1u], results[r + 2u]);
      if (!isnan(v.x)) light += dvec3(v);
    }
    acc_bounce[at] = light.x, acc_bounce[at + 1u] = light.y, acc_bounce[at + 2u] = light.z;
  }
  acc_samples[texel] += samples;
  // Per-bounce layer passes record no bounce layers: the first slot counts back faces instead.
  if ((params.bounce_flags & kBouncePass) != 0u) acc_bounce[texel * 3u] += double(back_faces);
  if (nonfinite > 0u) atomicAdd(counters[kCounterNonfinite], nonfinite);
}
