#version 460
#extension GL_GOOGLE_include_directive : require
// The voxel exitance of what the runtime shows, computed on the device from a published estimate
// (vulkan/voxel_exitance_publishing.h; docs/runtime.md "Voxel exitance"): what fill_svo_exitance
// does on the host, without the half-float encoding. Pass 0 (per leaf side): the area-weighted sum
// of M = pi (emitted + albedo E/pi) over the texels deposited there (texel_exitance.h
// voxel_deposits), in G-buffer order; pass 1 (per node of a level, deepest first): the sums of its
// children, flipped where a child faces away; pass 2 (every node): the side's mean, lit where it
// has weight; pass 3 (per node of a level, root first): an unlit side takes its parent's value
// (filled) where that has one. Output: [node][front rgb, back rgb], 0 where neither lit nor filled.
layout(local_size_x = 64) in;

#include "exitance/common/sampling.h"  // kPi, as texel_exitance.cpp's

layout(std430, set = 0, binding = 0) readonly buffer Sums { double sums[]; };      // [texel][total rgb, squared rgb]
layout(std430, set = 0, binding = 1) readonly buffer Samples { uint samples[]; };  // [texel]
layout(std430, set = 0, binding = 2) readonly buffer SideFirst { uint side_first[]; };
layout(std430, set = 0, binding = 3) readonly buffer Entries { float entries[]; };  // [entry][texel bits, weight, emitted rgb, albedo rgb, 0]
layout(std430, set = 0, binding = 4) readonly buffer Nodes { uint nodes[]; };       // [node][parent, first child, children, flipped]
layout(std430, set = 0, binding = 5) buffer Scratch { double scratch[]; };          // [side][sum rgb, weight]
layout(std430, set = 0, binding = 6) buffer Out { float out_m[]; };                 // [node][front rgb, back rgb]
layout(std430, set = 0, binding = 7) buffer State { uint state[]; };                // [side]: 0 none, 1 lit, 2 filled

layout(push_constant) uniform Push {
  uint pass_index;
  uint first;  // node range [first, first + count)
  uint count;
} push;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= push.count) return;
  uint node = push.first + i;
  if (push.pass_index == 0u) {
    for (uint side = 0u; side < 2u; ++side) {
      uint s = node * 2u + side;
      dvec3 sum = dvec3(0.0lf);
      double weight = 0.0lf;
      for (uint e = side_first[s]; e < side_first[s + 1u]; ++e) {
        uint t = floatBitsToUint(entries[e * 9u]);
        uint n = samples[t];
        if (n == 0u) continue;
        float w = entries[e * 9u + 1u];
        precise vec3 mean = vec3(float(sums[t * 6u] / double(n)), float(sums[t * 6u + 1u] / double(n)), float(sums[t * 6u + 2u] / double(n)));
        precise vec3 m = (vec3(entries[e * 9u + 2u], entries[e * 9u + 3u], entries[e * 9u + 4u]) +
                          vec3(entries[e * 9u + 5u], entries[e * 9u + 6u], entries[e * 9u + 7u]) * mean) * kPi;
        if (any(isnan(m)) || any(isinf(m)) || !(w > 0.0)) continue;
        sum += dvec3(m) * double(w);
        weight += double(w);
      }
      for (uint c = 0u; c < 3u; ++c) scratch[s * 4u + c] = sum[c];
      scratch[s * 4u + 3u] = weight;
    }
  } else if (push.pass_index == 1u) {
    uint first_child = nodes[node * 4u + 1u], children = nodes[node * 4u + 2u];
    for (uint j = first_child; j < first_child + children; ++j) {
      bool flipped = nodes[j * 4u + 3u] != 0u;
      for (uint side = 0u; side < 2u; ++side) {
        uint to = node * 2u + (flipped ? 1u - side : side);
        for (uint k = 0u; k < 4u; ++k) scratch[to * 4u + k] += scratch[(j * 2u + side) * 4u + k];
      }
    }
  } else if (push.pass_index == 2u) {
    for (uint side = 0u; side < 2u; ++side) {
      uint s = node * 2u + side;
      double weight = scratch[s * 4u + 3u];
      bool lit = weight > 0.0lf;
      for (uint c = 0u; c < 3u; ++c) out_m[s * 3u + c] = lit ? max(float(scratch[s * 4u + c] / weight), 0.0) : 0.0;
      state[s] = lit ? 1u : 0u;
    }
  } else {
    uint parent = nodes[node * 4u];
    bool flipped = nodes[node * 4u + 3u] != 0u;
    for (uint side = 0u; side < 2u; ++side) {
      uint s = node * 2u + side;
      if (state[s] == 1u) continue;
      uint from = parent * 2u + (flipped ? 1u - side : side);
      if (state[from] == 0u) continue;
      for (uint c = 0u; c < 3u; ++c) out_m[s * 3u + c] = out_m[from * 3u + c];
      state[s] = 2u;
    }
  }
}
