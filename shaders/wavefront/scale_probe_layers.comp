#version 460
#extension GL_GOOGLE_include_directive : require
// An edit that only scaled lights' emission, on the runtime's refreshed probes (vulkan/probe_refresh.h,
// docs/runtime.md "Probes"): exact, as scale_light_layers.comp does for texels. Each scaled layer's
// SH sums times its factor (per channel), the totals by the layers' change; the squared L0 sums,
// which are not kept per light, follow the L0 total in proportion (squared), channel by channel.
// Sums: wavefront_buffers.h ProbeAccumulators (totals, squared L0, then [layer][probe][coefficient][rgb]).
layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) buffer Sums { double sums[]; };
layout(std430, set = 0, binding = 1) readonly buffer Factors { vec4 factors[]; };  // per scaled layer: rgb, w its light layer

layout(push_constant) uniform Push {
  uint probe_count;
  uint scaled;  // entries of `factors`
} push;

void main() {
  uint p = gl_GlobalInvocationID.x;
  uint N = push.probe_count;
  if (p >= N) return;
  double change[27];
  for (uint i = 0u; i < 27u; ++i) change[i] = 0.0lf;
  for (uint s = 0u; s < push.scaled; ++s) {
    vec4 f = factors[s];
    uint at = N * 30u + (uint(f.w) * N + p) * 27u;
    for (uint i = 0u; i < 27u; ++i) {
      double before = sums[at + i];
      double after = before * double(f[i % 3u]);
      change[i] += after - before;
      sums[at + i] = after;
    }
  }
  for (uint i = 0u; i < 27u; ++i) {
    double before = sums[p * 27u + i];
    // The L0 terms are sums of non-negative radiance: a total that rounding would take below 0 is 0.
    double after = i < 3u ? max(before + change[i], 0.0lf) : before + change[i];
    sums[p * 27u + i] = after;
    if (i < 3u) {
      double ratio = before > 0.0lf ? after / before : 1.0lf;
      sums[N * 27u + p * 3u + i] *= ratio * ratio;
    }
  }
}
