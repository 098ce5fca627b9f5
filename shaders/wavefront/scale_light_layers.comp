#version 460
#extension GL_GOOGLE_include_directive : require
// An edit that only scaled lights' emission (RefreshSession::apply_edits, docs/runtime.md "Light
// layers"), on one estimate in the wavefront's texel-sum layout (wavefront_buffers.h
// TexelAccumulators). Exact (an estimate whose light layers split its totals: the accumulation, or
// one composed from it alone): each scaled layer times its factor, and the total by the layers'
// change. Proportional (one without that split: the baked lightmap, whose bundle has no layers, or
// what was published from it): the change in proportion to the accumulation's split at that texel
// (unchanged where the accumulation has no sample there). What is not kept per light (the squared
// totals, the recorded bounce layers, the L1 sums) follows the total in proportion, channel by
// channel. The accumulation is dispatched last, after the other estimates have read it. The cost is
// per scaled layer, not per layer.
layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) buffer Sums { double sums[]; };      // [texel][total rgb, squared rgb], then L1
layout(std430, set = 0, binding = 1) buffer Layers { double layers[]; };  // [recorded + light layer][texel][rgb]
layout(std430, set = 0, binding = 2) readonly buffer Factors { vec4 factors[]; };  // per scaled layer: rgb, w its light layer
layout(std430, set = 0, binding = 3) readonly buffer AccumulatedSums { double acc_sums[]; };
layout(std430, set = 0, binding = 4) readonly buffer AccumulatedLayers { double acc_layers[]; };

layout(push_constant) uniform Push {
  uint texel_count;
  uint recorded;
  uint scaled;       // entries of `factors`
  uint directional;
  uint proportional;  // 1: this estimate's layers do not split its totals
} push;

void main() {
  uint t = gl_GlobalInvocationID.x;
  uint N = push.texel_count;
  if (t >= N) return;
  bool exact = push.proportional == 0u;
  dvec3 change = dvec3(0.0lf);
  for (uint s = 0u; s < push.scaled; ++s) {
    vec4 f = factors[s];
    uint at = ((push.recorded + uint(f.w)) * N + t) * 3u;
    for (uint c = 0u; c < 3u; ++c) {
      double before = exact ? layers[at + c] : acc_layers[at + c];
      double after = before * double(f[c]);
      change[c] += after - before;
      if (exact) layers[at + c] = after;
    }
  }
  for (uint c = 0u; c < 3u; ++c) {
    double before = sums[t * 6u + c];
    double ratio = 1.0lf;
    if (exact) {
      // Layers are sums of non-negative contributions: a total that rounding would take below 0 is 0.
      double after = max(before + change[c], 0.0lf);
      ratio = before > 0.0lf ? after / before : 1.0lf;
      sums[t * 6u + c] = after;
    } else {
      double acc_before = acc_sums[t * 6u + c];
      ratio = acc_before > 0.0lf ? max(acc_before + change[c], 0.0lf) / acc_before : 1.0lf;
      sums[t * 6u + c] = before * ratio;
    }
    sums[t * 6u + 3u + c] *= ratio * ratio;
    for (uint k = 0u; k < push.recorded; ++k) layers[(k * N + t) * 3u + c] *= ratio;
    if (push.directional != 0u)
      for (uint axis = 0u; axis < 3u; ++axis) sums[N * 6u + t * 9u + axis * 3u + c] *= ratio;
  }
}
