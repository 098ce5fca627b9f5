#version 460
#extension GL_GOOGLE_include_directive : require
// An edit that only scaled lights' emission (RefreshSession::apply_edits, docs/runtime.md "Light
// layers"), on one estimate in the wavefront's texel-sum layout (wavefront_buffers.h
// TexelAccumulators). Per texel whose light layers split its total (they add up to it): each
// scaled layer times its factor, exactly, and the total by the layers' change. A texel without
// such a split (the baked lightmap, whose bundle has no layers; a change estimate's result) takes
// the change in proportion to the accumulation's split at that texel (unchanged where the
// accumulation has no sample there). What is not kept per light (the squared totals, the recorded
// bounce layers, the L1 sums) follows the total in proportion, channel by channel. The accumulation
// is dispatched last, after every other estimate has read it.
layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) buffer Sums { double sums[]; };      // [texel][total rgb, squared rgb], then L1
layout(std430, set = 0, binding = 1) buffer Layers { double layers[]; };  // [recorded + light layer][texel][rgb]
layout(std430, set = 0, binding = 2) readonly buffer Factors { vec4 factors[]; };  // per light layer: rgb, w 1 when scaled
layout(std430, set = 0, binding = 3) readonly buffer AccumulatedSums { double acc_sums[]; };
layout(std430, set = 0, binding = 4) readonly buffer AccumulatedLayers { double acc_layers[]; };

layout(push_constant) uniform Push {
  uint texel_count;
  uint recorded;
  uint light_layers;
  uint directional;
  uint accumulation;  // 1: this estimate is the accumulation (its layers always split its totals)
} push;

// Light layers add up to the total within the rounding of their different orders of addition.
const double kSplitTolerance = 1e-4lf;

void main() {
  uint t = gl_GlobalInvocationID.x;
  uint N = push.texel_count;
  if (t >= N) return;
  dvec3 layer_sum = dvec3(0.0lf), change = dvec3(0.0lf), acc_change = dvec3(0.0lf);
  for (uint l = 0u; l < push.light_layers; ++l) {
    vec4 f = factors[l];
    uint at = ((push.recorded + l) * N + t) * 3u;
    for (uint c = 0u; c < 3u; ++c) {
      layer_sum[c] += layers[at + c];
      if (f.w != 0.0) {
        change[c] += layers[at + c] * double(f[c]) - layers[at + c];
        acc_change[c] += acc_layers[at + c] * double(f[c]) - acc_layers[at + c];
      }
    }
  }
  bool split = push.accumulation != 0u;
  if (!split) {
    split = true;
    for (uint c = 0u; c < 3u; ++c) split = split && abs(layer_sum[c] - sums[t * 6u + c]) <= kSplitTolerance * abs(sums[t * 6u + c]);
  }
  for (uint c = 0u; c < 3u; ++c) {
    double before = sums[t * 6u + c];
    double ratio = 1.0lf;
    if (split) {
      // Layers are sums of non-negative contributions: a total that rounding would take below 0 is 0.
      double after = max(before + change[c], 0.0lf);
      ratio = before > 0.0lf ? after / before : 1.0lf;
      sums[t * 6u + c] = after;
    } else {
      double acc_before = acc_sums[t * 6u + c];
      ratio = acc_before > 0.0lf ? max(acc_before + acc_change[c], 0.0lf) / acc_before : 1.0lf;
      sums[t * 6u + c] = before * ratio;
    }
    sums[t * 6u + 3u + c] *= ratio * ratio;
    for (uint k = 0u; k < push.recorded; ++k) layers[(k * N + t) * 3u + c] *= ratio;
    if (push.directional != 0u)
      for (uint axis = 0u; axis < 3u; ++axis) sums[N * 6u + t * 9u + axis * 3u + c] *= ratio;
  }
  // The layers last: the sums above read their values from before.
  for (uint l = 0u; l < push.light_layers; ++l) {
    vec4 f = factors[l];
    if (f.w == 0.0) continue;
    uint at = ((push.recorded + l) * N + t) * 3u;
    for (uint c = 0u; c < 3u; ++c) layers[at + c] = split ? layers[at + c] * double(f[c]) : layers[at + c];
  }
}
