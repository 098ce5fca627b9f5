#version 460
#extension GL_GOOGLE_include_directive : require
// The per-bounce mode's layer cache built on the device (issue 34, item 1; vulkan/bounce_layer_driver.h):
// BounceLayerCache::build's pages of layer k in the cache buffer (gpu_layout.h kBindingBounceCache,
// kBounceCacheTexelWords per page texel), from the layer's per-texel means, so the layer passes read
// it with no host build, interleave or upload of the pages. Three modes, dispatched in order:
//  0 clear: every page texel's words and its fill flag to 0;
//  1 write: each valid live texel's mean, lit = 1, position and geometric normal at its page texel
//    (flag 1);
//  2 ring r (1, 2, ...): lightmap_assembly.h dilate_into_gutter's pass r: an unfilled page texel with
//    filled 8-neighbours (flag 1..r, i.e. filled before this ring) takes every word's mean over them,
//    summed in double in the same order, so the pages are the host's bit for bit; its flag becomes
//    r + 1, which this ring's other texels do not count.
layout(local_size_x = 64) in;
#include "exitance/common/gpu_layout.h"

layout(std430, set = 0, binding = 0) buffer Cache { float cache[]; };
// Per live texel 8 words: its page texel (over all pages; 0xFFFFFFFF: none), position xyz, normal xyz, 0.
layout(std430, set = 0, binding = 1) readonly buffer Texels { uint texel_words[]; };
layout(std430, set = 0, binding = 2) readonly buffer Means { vec4 means[]; };  // rgb, w: 1 valid, 0 left out
layout(std430, set = 0, binding = 3) buffer Flags { uint flags[]; };           // per page texel
layout(std430, set = 0, binding = 4) readonly buffer Pages { uvec4 pages[]; }; // width, height, first page texel, 0

layout(push_constant) uniform Push {
  uint mode;
  uint layer_word;  // the layer's first word in the cache
  uint count;       // live texels (write) or page texels (clear, ring)
  uint ring;
  uint page_count;
} push;

const uint kWords = kBounceCacheTexelWords;

void main() {
  uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  if (i >= push.count) return;
  if (push.mode == 0u) {
    for (uint c = 0u; c < kWords; ++c) cache[push.layer_word + i * kWords + c] = 0.0;
    flags[i] = 0u;
    return;
  }
  if (push.mode == 1u) {
    vec4 m = means[i];
    uint g = texel_words[i * 8u];
    if (!(m.w > 0.0) || g == 0xFFFFFFFFu) return;
    uint at = push.layer_word + g * kWords;
    cache[at] = m.x;
    cache[at + 1u] = m.y;
    cache[at + 2u] = m.z;
    cache[at + 3u] = 1.0;
    for (uint c = 0u; c < 6u; ++c) cache[at + 4u + c] = uintBitsToFloat(texel_words[i * 8u + 1u + c]);
    flags[g] = 1u;
    return;
  }
  if (flags[i] != 0u) return;
  uvec4 page = uvec4(0u);
  for (uint p = 0u; p < push.page_count; ++p)
    if (i >= pages[p].z && i < pages[p].z + pages[p].x * pages[p].y) page = pages[p];
  int width = int(page.x), height = int(page.y);
  if (width == 0) return;
  int x = int(i - page.z) % width, y = int(i - page.z) / width;
  double sum[kWords];
  for (uint c = 0u; c < kWords; ++c) sum[c] = 0.0lf;
  int n = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      int nx = x + dx, ny = y + dy;
      if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
      uint j = page.z + uint(ny) * uint(width) + uint(nx);
      uint f = flags[j];
      if (f == 0u || f > push.ring) continue;
      for (uint c = 0u; c < kWords; ++c) sum[c] += double(cache[push.layer_word + j * kWords + c]);
      ++n;
    }
  if (n == 0) return;
  for (uint c = 0u; c < kWords; ++c) cache[push.layer_word + i * kWords + c] = float(sum[c] / double(n));
  flags[i] = push.ring + 1u;
}
