#version 460
#extension GL_GOOGLE_include_directive : require
// What each texel publishes, on the device (runtime/src/vulkan/device_lightmaps.h): per texel, the
// progressive accumulation, the previous estimate (what it showed before the last edit) or a change
// estimate's base, by publishing_rule.h, the rule refresh/published_estimate.cpp applies on the host
// (publish_restart, publish_change: the same arithmetic, so the same choices and values). Reads the
// accumulation and two device estimates, writes a third; counts the published texels with one sample
// and with two or more (whether the result can be a change estimate's base).
// Every estimate has the layout of the wavefront's texel sums (wavefront_buffers.h TexelAccumulators):
// sums [texel][total rgb, squared rgb] then, directional, [texel][axis][rgb] of L1; layers
// [layer][texel][rgb]; samples [texel].
layout(local_size_x = 64) in;
#include "exitance/common/publishing_rule.h"

layout(std430, set = 0, binding = 0) readonly buffer AccumulatedSums { double acc_sums[]; };
layout(std430, set = 0, binding = 1) readonly buffer AccumulatedLayers { double acc_layers[]; };
layout(std430, set = 0, binding = 2) readonly buffer AccumulatedSamples { uint acc_samples[]; };
layout(std430, set = 0, binding = 3) readonly buffer PreviousSums { double prev_sums[]; };
layout(std430, set = 0, binding = 4) readonly buffer PreviousLayers { double prev_layers[]; };
layout(std430, set = 0, binding = 5) readonly buffer PreviousSamples { uint prev_samples[]; };
layout(std430, set = 0, binding = 6) readonly buffer BaseSums { double base_sums[]; };
layout(std430, set = 0, binding = 7) readonly buffer BaseLayers { double base_layers[]; };
layout(std430, set = 0, binding = 8) readonly buffer BaseSamples { uint base_samples[]; };
layout(std430, set = 0, binding = 9) writeonly buffer OutSums { double out_sums[]; };
layout(std430, set = 0, binding = 10) writeonly buffer OutLayers { double out_layers[]; };
layout(std430, set = 0, binding = 11) writeonly buffer OutSamples { uint out_samples[]; };
layout(std430, set = 0, binding = 12) buffer Counts { uint counts[]; };  // [one sample, two or more]

// device_lightmaps.cpp PublishMode.
const uint kModeAccumulation = 0u;  // the accumulation as it is (nothing before it)
const uint kModeRestart = 1u;       // publish_restart(previous, accumulation)
const uint kModeChange = 2u;        // publish_change(previous, base, accumulation)

layout(push_constant) uniform Push {
  uint texel_count;
  uint layers;
  uint directional;
  uint mode;
} push;

// Which estimate a source index names.
const uint kFromAccumulation = 0u, kFromPrevious = 1u, kFromBase = 2u;

double sum_of(uint from, uint i) {
  if (from == kFromPrevious) return prev_sums[i];
  if (from == kFromBase) return base_sums[i];
  return acc_sums[i];
}
double layer_of(uint from, uint i) {
  if (from == kFromPrevious) return prev_layers[i];
  if (from == kFromBase) return base_layers[i];
  return acc_layers[i];
}
uint samples_of(uint from, uint t) {
  if (from == kFromPrevious) return prev_samples[t];
  if (from == kFromBase) return base_samples[t];
  return acc_samples[t];
}

// LightmapEstimate::mean_total's rounding: a float per channel.
vec3 mean_total(uint from, uint t) {
  uint n = samples_of(from, t);
  if (n == 0u) return vec3(0.0);
  double d = double(n);
  return vec3(float(sum_of(from, t * 6u) / d), float(sum_of(from, t * 6u + 1u) / d), float(sum_of(from, t * 6u + 2u) / d));
}
double variance_sum(uint from, uint t) {
  uint n = samples_of(from, t);
  double v = 0.0lf;
  for (uint c = 0u; c < 3u; ++c) v += double(variance_of_mean_from_sums(sum_of(from, t * 6u + c), sum_of(from, t * 6u + 3u + c), n));
  return v;
}

void copy_texel(uint from, uint t) {
  uint N = push.texel_count;
  for (uint k = 0u; k < 6u; ++k) out_sums[t * 6u + k] = sum_of(from, t * 6u + k);
  if (push.directional != 0u)
    for (uint k = 0u; k < 9u; ++k) out_sums[N * 6u + t * 9u + k] = sum_of(from, N * 6u + t * 9u + k);
  for (uint l = 0u; l < push.layers; ++l)
    for (uint c = 0u; c < 3u; ++c) out_layers[(l * N + t) * 3u + c] = layer_of(from, (l * N + t) * 3u + c);
  out_samples[t] = samples_of(from, t);
}

// add_change (published_estimate.cpp) for a texel where both have samples: means add, variances of
// the mean add, over the sum of the sample counts; the sums are synthesized (set_total_sums).
uint write_base_plus_change(uint t) {
  uint N = push.texel_count;
  uint nb = base_samples[t], nd = acc_samples[t];
  double m = double(nb) + double(nd);
  double b = double(nb), d = double(nd);
  for (uint c = 0u; c < 3u; ++c) {
    double mean = base_sums[t * 6u + c] / b + acc_sums[t * 6u + c] / d;
    double variance = double(variance_of_mean_from_sums(base_sums[t * 6u + c], base_sums[t * 6u + 3u + c], nb)) +
                      double(variance_of_mean_from_sums(acc_sums[t * 6u + c], acc_sums[t * 6u + 3u + c], nd));
    uint samples = uint(m);
    double n = double(samples);
    out_sums[t * 6u + c] = n * mean;
    out_sums[t * 6u + 3u + c] = n * mean * mean + n * (n - 1.0lf) * variance;
  }
  for (uint l = 0u; l < push.layers; ++l)
    for (uint c = 0u; c < 3u; ++c) {
      uint at = (l * N + t) * 3u + c;
      out_layers[at] = m * (base_layers[at] / b + acc_layers[at] / d);
    }
  if (push.directional != 0u)
    for (uint k = 0u; k < 9u; ++k) {
      uint at = N * 6u + t * 9u + k;
      out_sums[at] = m * (base_sums[at] / b + acc_sums[at] / d);
    }
  out_samples[t] = uint(m);
  return uint(m);
}

// What texel t publishes, written to the out estimate; returns its sample count.
uint publish_texel(uint t) {
  uint published_samples;
  if (push.mode == kModeRestart) {
    vec3 k = mean_total(kFromPrevious, t), f = mean_total(kFromAccumulation, t);
    double difference = 0.0lf;
    for (uint c = 0u; c < 3u; ++c) difference += (double(f[c]) - double(k[c])) * (double(f[c]) - double(k[c]));
    bool all_zero = acc_sums[t * 6u] == 0.0lf && acc_sums[t * 6u + 1u] == 0.0lf && acc_sums[t * 6u + 2u] == 0.0lf;
    uint choice = publish_after_restart(prev_samples[t], acc_samples[t], difference, variance_sum(kFromPrevious, t),
                                        variance_sum(kFromAccumulation, t), all_zero);
    uint from = choice == kPublishPrevious ? kFromPrevious : kFromAccumulation;
    copy_texel(from, t);
    published_samples = samples_of(from, t);
  } else if (push.mode == kModeChange) {
    vec3 d = mean_total(kFromAccumulation, t);
    double squared = double(d[0]) * double(d[0]) + double(d[1]) * double(d[1]) + double(d[2]) * double(d[2]);
    uint choice = publish_after_change(base_samples[t], acc_samples[t], squared, variance_sum(kFromAccumulation, t));
    if (choice == kPublishRefreshed) {
      published_samples = write_base_plus_change(t);
    } else {
      uint from = choice == kPublishPrevious ? kFromPrevious : kFromBase;
      copy_texel(from, t);
      published_samples = samples_of(from, t);
    }
  } else {
    copy_texel(kFromAccumulation, t);
    published_samples = acc_samples[t];
  }
  return published_samples;
}

// The counts added per workgroup first: a million atomics on one address each (one per texel)
// serialize in the device's cache; one per workgroup and counter do not.
shared uint group_counts[2];

void main() {
  uint t = gl_GlobalInvocationID.x;
  if (gl_LocalInvocationIndex == 0u) group_counts[0] = 0u, group_counts[1] = 0u;
  memoryBarrierShared();
  barrier();
  if (t < push.texel_count) {
    uint published_samples = publish_texel(t);
    if (published_samples == 1u) atomicAdd(group_counts[0], 1u);
    if (published_samples >= 2u) atomicAdd(group_counts[1], 1u);
  }
  memoryBarrierShared();
  barrier();
  if (gl_LocalInvocationIndex == 0u) {
    if (group_counts[0] > 0u) atomicAdd(counts[0], group_counts[0]);
    if (group_counts[1] > 0u) atomicAdd(counts[1], group_counts[1]);
  }
}
