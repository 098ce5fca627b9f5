#version 460
#extension GL_GOOGLE_include_directive : require
// What the runtime's refreshed probes show, written into a device buffer an engine reads (the C API's
// exitance_runtime_publish_probes; docs/runtime.md "Probes"): per refreshed probe the choice of
// refresh/published_probes.cpp's probe_shows_refreshed (publishing_rule.h's publish_after_restart on
// L0, or the switch count where the kept value's variance is unknown) between its refreshed
// estimate (mean SH times the bake's dering window per band, as store_probe_radiance writes it) and
// what it showed before the last edit, into its grid slot: 27 floats, coefficient i, channel c at
// [i * 3 + c]. The same float operations as the host, so the buffer equals published_probes().
layout(local_size_x = 64) in;
#include "exitance/common/publishing_rule.h"
#include "exitance/common/spherical_harmonics_basis.h"

layout(std430, set = 0, binding = 0) readonly buffer Sums { double sums[]; };    // ProbeAccumulators: totals, squared L0, ...
layout(std430, set = 0, binding = 1) readonly buffer Counts { uint counts[]; };  // [probe][samples, back faces]
// [probe][27 sh, samples, variance (< 0: unknown); a change estimate's base: 27 sh, samples]
layout(std430, set = 0, binding = 2) readonly buffer Kept { double kept[]; };
layout(std430, set = 0, binding = 3) readonly buffer GridIndex { uint grid_index[]; };  // per refreshed probe its slot
layout(std430, set = 0, binding = 4) writeonly buffer Out { float out_sh[]; };          // [grid probe][27]

layout(push_constant) uniform Push {
  uint probe_count;
  uint switch_samples;
  float band_weight[3];  // the dering window per SH band (1 without dering)
  uint change;           // 1: the sums estimate a change of the lights from the kept base
} push;

const uint kKeptWords = 57u;
const uint kBaseAt = 29u;

// The variance of probe k's L0 mean, summed over rgb, from its sums over n samples, as
// ProbeEstimate::l0_variance_of_mean adds it (0 below 2 samples).
double l0_variance_of_mean(uint k, uint n) {
  double variance = 0.0lf;
  uint squares_at = push.probe_count * 27u + k * 3u;
  for (uint c = 0u; c < 3u; ++c) variance += double(variance_of_mean_from_sums(sums[k * 27u + c], sums[squares_at + c], n));
  return variance;
}

// During a change estimate (refresh/published_probes.cpp probe_change_choice): publish_after_change
// on the change's L0 terms chooses what the probe showed before the last edit, the base, or the base
// plus the change's mean (times the dering window per band; the base as shown is deringed already).
void publish_change(uint k, uint n, uint at, uint out_at) {
  double squared = 0.0lf;
  if (n > 0u)
    for (uint c = 0u; c < 3u; ++c) {
      double d = sums[k * 27u + c] / double(n);
      squared += d * d;
    }
  uint choice = publish_after_change(uint(kept[at + kBaseAt + 27u]), n, squared, l0_variance_of_mean(k, n));
  for (uint i = 0u; i < 27u; ++i) {
    precise float value;
    if (choice == kPublishPrevious) {
      value = float(kept[at + i]);
    } else {
      float base = float(kept[at + kBaseAt + i]);
      value = base;
      if (choice == kPublishRefreshed) {
        precise float change = float(sums[k * 27u + i] / double(n)) * push.band_weight[sh_band(int(i / 3u))];
        precise float sum = base + change;
        if (!isnan(sum) && !isinf(sum)) value = sum;
      }
    }
    out_sh[out_at + i] = value;
  }
}


void main() {
  uint k = gl_GlobalInvocationID.x;
  if (k >= push.probe_count) return;
  uint n = counts[k * 2u];
  uint at = k * kKeptWords;
  if (push.change != 0u) {
    publish_change(k, n, at, grid_index[k] * 27u);
    return;
  }
  double difference_squared = 0.0lf;
  bool all_zero = true;
  if (n > 0u) {
    uint squares_at = push.probe_count * 27u + k * 3u;
    for (uint c = 0u; c < 3u; ++c) {
      double d = sums[k * 27u + c] / double(n) - double(float(kept[at + c]));
      difference_squared += d * d;
      all_zero = all_zero && sums[k * 27u + c] == 0.0lf && sums[squares_at + c] == 0.0lf;
    }
  }
  bool refreshed = publish_probe_refreshed(n, push.switch_samples, uint(kept[at + 27u]), kept[at + 28u], difference_squared,
                                           l0_variance_of_mean(k, n), all_zero);
  uint out_at = grid_index[k] * 27u;
  for (uint i = 0u; i < 9u; ++i) {
    vec3 value;
    for (uint c = 0u; c < 3u; ++c)
      value[c] = refreshed ? float(sums[k * 27u + i * 3u + c] / double(n)) * push.band_weight[sh_band(int(i))] : float(kept[at + i * 3u + c]);
    if (refreshed && (any(isnan(value)) || any(isinf(value)))) value = vec3(0.0);
    for (uint c = 0u; c < 3u; ++c) out_sh[out_at + i * 3u + c] = value[c];
  }
}
