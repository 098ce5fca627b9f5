#version 460
#extension GL_GOOGLE_include_directive : require
// The published lightmap into an atlas page image an engine samples (runtime/src/vulkan/
// lightmap_page_images.h): E/pi in RGB, coverage in A, gutters dilated as
// runtime/src/bundle/lightmap_assembly.cpp dilates them, so the image equals read_page's values bit
// for bit. Dispatched once per ring over the page: ring 0 writes live texels (and zeros), ring k > 0
// averages the neighbours of rings below k, which earlier dispatches wrote (a barrier in between).
layout(local_size_x = 8, local_size_y = 8) in;

// A device estimate (wavefront_buffers.h TexelAccumulators): sums [texel][total rgb, squared rgb].
layout(std430, set = 0, binding = 0) readonly buffer Sums { double sums[]; };
layout(std430, set = 0, binding = 1) readonly buffer Samples { uint samples[]; };
// Per pixel of every page: [texel, ring, coverage bits] (lightmap_page_images.cpp PagePixel).
layout(std430, set = 0, binding = 2) readonly buffer Pixels { uint pixels[]; };
layout(set = 0, binding = 3, rgba32f) uniform image2D page;

layout(push_constant) uniform Push {
  uint width;
  uint height;
  uint first_pixel;  // this page's first pixel in `pixels`
  uint ring;
} push;

const uint kNoTexel = 0xffffffffu;
const uint kNeverFilled = 0xffffffffu;

uint ring_at(uvec2 p) { return pixels[(push.first_pixel + p.y * push.width + p.x) * 3u + 1u]; }

void main() {
  uvec2 p = gl_GlobalInvocationID.xy;
  if (p.x >= push.width || p.y >= push.height) return;
  uint at = (push.first_pixel + p.y * push.width + p.x) * 3u;
  uint ring = pixels[at + 1u];
  float coverage = uintBitsToFloat(pixels[at + 2u]);
  if (push.ring == 0u) {
    // A pixel the dilation fills later is written then; every other one takes its texel (or 0).
    if (ring != 0u && ring != kNeverFilled) return;
    vec3 rgb = vec3(0.0);
    uint t = pixels[at];
    if (t != kNoTexel) {
      uint n = samples[t];
      if (n > 0u) {  // LightmapEstimate::mean_total's rounding: a float per channel
        double d = double(n);
        rgb = vec3(float(sums[t * 6u] / d), float(sums[t * 6u + 1u] / d), float(sums[t * 6u + 2u] / d));
      }
    }
    imageStore(page, ivec2(p), vec4(rgb, coverage));
    return;
  }
  if (ring != push.ring) return;
  // dilate_into's mean of the filled 8-neighbours: summed in double in the same order, then a float.
  dvec3 sum = dvec3(0.0);
  uint n = 0u;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      ivec2 q = ivec2(p) + ivec2(dx, dy);
      if (q.x < 0 || q.y < 0 || q.x >= int(push.width) || q.y >= int(push.height)) continue;
      if (ring_at(uvec2(q)) >= push.ring) continue;  // not filled before this ring (kNeverFilled too)
      sum += dvec3(imageLoad(page, q).rgb);
      ++n;
    }
  vec3 rgb = n > 0u ? vec3(sum / double(n)) : vec3(0.0);
  imageStore(page, ivec2(p), vec4(rgb, coverage));
}
