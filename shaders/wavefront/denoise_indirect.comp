#version 460
#extension GL_GOOGLE_include_directive : require
// The texture-space filter of a lightmap's indirect light on the device (runtime/src/vulkan/
// indirect_denoiser.h): runtime/src/bundle/indirect_denoise.cpp's arithmetic in the same order, with
// the neighbour weights of exitance/common/texture_space_filter.h, so a published estimate filtered
// here equals denoise_indirect's on the host up to the rounding of exp and sqrt.
// Pass 0 writes each texel's indirect mean (total minus layer 0, the direct light) and its variance
// of the mean; pass 1 (after a barrier) averages them over the atlas window and writes the filtered
// estimate: sums synthesized from the mean and variance (set_total_sums), layer 0 kept, layers 1 and
// up filtered with the same weights, sample counts kept. Estimates have the layout of the
// wavefront's texel sums (wavefront_buffers.h TexelAccumulators): sums [texel][total rgb, squared
// rgb], layers [layer][texel][rgb], samples [texel]; the output holds no L1 sums or light layers.
layout(local_size_x = 64) in;
#include "exitance/common/publishing_rule.h"
#include "exitance/common/texture_space_filter.h"

layout(std430, set = 0, binding = 0) readonly buffer InSums { double in_sums[]; };
layout(std430, set = 0, binding = 1) readonly buffer InLayers { double in_layers[]; };
layout(std430, set = 0, binding = 2) readonly buffer InSamples { uint in_samples[]; };
layout(std430, set = 0, binding = 3) writeonly buffer OutSums { double out_sums[]; };
layout(std430, set = 0, binding = 4) writeonly buffer OutLayers { double out_layers[]; };
layout(std430, set = 0, binding = 5) writeonly buffer OutSamples { uint out_samples[]; };
// Per texel (indirect_denoiser.cpp): [position, world texel size], [geometric normal, 0]; its page
// and atlas column | row << 16. Per page: its first pixel in texel_at, width, height.
layout(std430, set = 0, binding = 6) readonly buffer Texels { vec4 texel_records[]; };
layout(std430, set = 0, binding = 7) readonly buffer Where { uvec2 where[]; };
layout(std430, set = 0, binding = 8) readonly buffer Pages { uvec4 pages[]; };
layout(std430, set = 0, binding = 9) readonly buffer Pixels { uint texel_at[]; };  // per page pixel: its texel or kNone
layout(std430, set = 0, binding = 10) buffer Indirect { vec4 indirect[]; };        // [texel][mean, variance of the mean]
layout(std430, set = 0, binding = 11) buffer Counts { uint counts[]; };            // [texels filtered, neighbours]

layout(push_constant) uniform Push {
  uint texel_count;
  uint layers;  // recorded layers (layer 0: the direct light)
  int radius;
  uint pass;
  uint totals_only;  // 1: only the sums and sample counts are written (all the page images read)
} push;

const uint kNone = 0xffffffffu;

shared uint group_filtered, group_neighbours;

void write_indirect(uint t) {
  uint n = in_samples[t];
  vec3 mean = vec3(0.0), variance = vec3(0.0);
  if (n > 0u) {
    double d = double(n);
    for (uint c = 0u; c < 3u; ++c) {
      // indirect_denoise.cpp: float((total - direct) / samples); variance_of_mean as the estimate's.
      mean[c] = float((in_sums[t * 6u + c] - in_layers[t * 3u + c]) / d);
      variance[c] = variance_of_mean_from_sums(in_sums[t * 6u + c], in_sums[t * 6u + 3u + c], n);
    }
  }
  indirect[t * 2u] = vec4(mean, 0.0);
  indirect[t * 2u + 1u] = vec4(variance, 0.0);
}

void copy_texel(uint t) {
  uint N = push.texel_count;
  for (uint k = 0u; k < 6u; ++k) out_sums[t * 6u + k] = in_sums[t * 6u + k];
  uint layers = push.totals_only != 0u ? 0u : push.layers;
  for (uint l = 0u; l < layers; ++l)
    for (uint c = 0u; c < 3u; ++c) out_layers[(l * N + t) * 3u + c] = in_layers[(l * N + t) * 3u + c];
  out_samples[t] = in_samples[t];
}

// Layers 1 and up are summed kLayersPerWindow at a time, each group in a pass over the window (the
// weights computed again, the same), so a thread keeps a few sums whatever the recorded layers.
const uint kLayersPerWindow = 3u;

// Returns the neighbours with a weight > 0 (the texel itself included); 0 for a texel not filtered.
uint filter_texel(uint t) {
  uint N = push.texel_count;
  uint n = in_samples[t];
  if (n == 0u) {
    copy_texel(t);
    return 0u;
  }
  vec4 a = texel_records[t * 2u], b = texel_records[t * 2u + 1u];
  vec3 position = a.xyz, normal = b.xyz;
  float texel_size = a.w;
  uvec2 at = where[t];
  uvec4 info = pages[at.x];
  int x = int(at.y & 0xffffu), y = int(at.y >> 16u);
  vec3 own = indirect[t * 2u].xyz, own_variance = indirect[t * 2u + 1u].xyz;
  double d = double(n);
  int r = push.radius;
  uint neighbours = 0u;

  uint layers = push.totals_only != 0u ? 1u : push.layers;
  for (uint first = 1u; first == 1u || first < layers; first += kLayersPerWindow) {
    bool totals = first == 1u;
    double weight_sum = 0.0lf;
    dvec3 sum = dvec3(0.0lf), variance_sum = dvec3(0.0lf);
    dvec3 layer_sum[kLayersPerWindow];
    for (uint q = 0u; q < kLayersPerWindow; ++q) layer_sum[q] = dvec3(0.0lf);
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx) {
        int px = x + dx, py = y + dy;
        if (px < 0 || py < 0 || px >= int(info.y) || py >= int(info.z)) continue;
        uint j = texel_at[info.x + uint(py) * info.y + uint(px)];
        if (j == kNone || in_samples[j] == 0u) continue;
        vec4 ja = texel_records[j * 2u], jb = texel_records[j * 2u + 1u];
        double w = double(texture_space_filter_weight(position, normal, texel_size, ja.xyz, jb.xyz, dx, dy, r));
        if (w <= 0.0lf) continue;
        vec3 other = indirect[j * 2u].xyz, other_variance = indirect[j * 2u + 1u].xyz;
        float difference = 0.0f, variances = 0.0f;
        for (uint c = 0u; c < 3u; ++c) {
          difference += (other[c] - own[c]) * (other[c] - own[c]);
          variances += own_variance[c] + other_variance[c];
        }
        w *= double(texture_space_filter_range_weight(difference, variances));
        if (w <= 0.0lf) continue;
        weight_sum += w;
        if (totals) {
          ++neighbours;
          for (uint c = 0u; c < 3u; ++c) {
            sum[c] += w * double(other[c]);
            variance_sum[c] += w * w * double(other_variance[c]);
          }
        }
        if (first >= layers) continue;
        // indirect_denoise.cpp divides each term by the samples; one reciprocal per neighbour here
        // (a double division is many instructions on a GPU; the results differ in the last bit).
        double per_sample = w / double(in_samples[j]);
        for (uint q = 0u; q < kLayersPerWindow; ++q) {
          uint k = first + q;
          if (k >= layers) break;
          for (uint c = 0u; c < 3u; ++c) layer_sum[q][c] += per_sample * in_layers[(k * N + j) * 3u + c];
        }
      }
    // The texel itself always has weight 1 (same surface, offset 0), so weight_sum >= 1.
    if (totals)
      for (uint c = 0u; c < 3u; ++c) {
        double mean = in_layers[t * 3u + c] / d + sum[c] / weight_sum;
        double variance_of_mean = variance_sum[c] / (weight_sum * weight_sum);
        out_sums[t * 6u + c] = d * mean;  // set_total_sums
        out_sums[t * 6u + 3u + c] = d * mean * mean + d * (d - 1.0lf) * variance_of_mean;
        if (push.totals_only == 0u) out_layers[t * 3u + c] = in_layers[t * 3u + c];  // the direct light, kept
      }
    for (uint q = 0u; q < kLayersPerWindow; ++q) {
      uint k = first + q;
      if (k >= layers) break;
      for (uint c = 0u; c < 3u; ++c) out_layers[(k * N + t) * 3u + c] = d * layer_sum[q][c] / weight_sum;
    }
  }
  out_samples[t] = n;
  return neighbours;
}

void main() {
  uint t = gl_GlobalInvocationID.x;
  if (push.pass == 0u) {
    if (t < push.texel_count) write_indirect(t);
    return;
  }
  if (gl_LocalInvocationIndex == 0u) group_filtered = 0u, group_neighbours = 0u;
  barrier();
  if (t < push.texel_count) {
    uint neighbours = filter_texel(t);
    if (neighbours > 0u) {
      atomicAdd(group_filtered, 1u);
      atomicAdd(group_neighbours, neighbours);
    }
  }
  barrier();
  if (gl_LocalInvocationIndex == 0u) {
    atomicAdd(counts[0], group_filtered);
    atomicAdd(counts[1], group_neighbours);
  }
}
