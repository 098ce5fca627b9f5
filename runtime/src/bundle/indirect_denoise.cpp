#include "exitance/runtime/bundle/indirect_denoise.h"

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <vector>

#include "exitance/common/texture_space_filter.h"
#include "exitance/runtime/core/parallel_chunks.h"

namespace exitance {

LightmapEstimate denoise_indirect(const LightmapEstimate& estimate, const TexelGBuffer& gbuffer,
                                  const IndirectDenoiseSettings& settings, IndirectDenoiseReport* report) {
  const auto start = std::chrono::steady_clock::now();
  const size_t n = gbuffer.texels.size();
  if (estimate.texels.size() != n)
    throw std::invalid_argument("denoise_indirect: the estimate has " + std::to_string(estimate.texels.size()) +
                                " texels, the G-buffer " + std::to_string(n));
  if (estimate.light_layers > 0 || estimate.has_sh1())
    throw std::invalid_argument("denoise_indirect: light layers and L1 sums are not split into direct and indirect light");
  if (settings.radius < 1 || settings.radius > kFilterMaxRadius)
    throw std::invalid_argument("denoise_indirect: radius " + std::to_string(settings.radius) + " is not 1 to " +
                                std::to_string(kFilterMaxRadius));

  // Per page pixel, its live texel (or none): the neighbours of a texel are found by atlas offset.
  std::vector<size_t> page_first(gbuffer.pages.size() + 1, 0);
  for (size_t p = 0; p < gbuffer.pages.size(); ++p)
    page_first[p + 1] = page_first[p] + size_t(gbuffer.pages[p].width) * size_t(gbuffer.pages[p].height);
  constexpr uint32_t kNone = 0xffffffffu;
  std::vector<uint32_t> texel_at(page_first.back(), kNone);
  for (size_t i = 0; i < n; ++i) {
    const LiveTexel& t = gbuffer.texels[i];
    texel_at[page_first[t.page] + size_t(t.y) * size_t(gbuffer.pages[t.page].width) + t.x] = uint32_t(i);
  }

  // Each texel's indirect mean (total minus direct) per channel, and its variance of the mean.
  std::vector<Vec3> indirect(n), variance(n);
  for_each_chunk(n, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const TexelAccumulator& a = estimate.texels[i];
      if (a.samples == 0) continue;
      for (int c = 0; c < 3; ++c) indirect[i][c] = float((a.total[c] - a.direct[c]) / a.samples);
      variance[i] = estimate.variance_of_mean(i);
    }
  });

  LightmapEstimate out = estimate;
  const int r = settings.radius, layers = estimate.recorded_bounces;
  std::atomic<uint64_t> filtered{0}, neighbours{0};
  for_each_chunk(n, [&](size_t begin, size_t end) {
    uint64_t my_filtered = 0, my_neighbours = 0;
    std::vector<double> layer_sum(size_t(layers) * 3);  // one per chunk, not per texel (no allocation in the loop)
    for (size_t i = begin; i < end; ++i) {
      const TexelAccumulator& a = estimate.texels[i];
      if (a.samples == 0) continue;
      const LiveTexel& t = gbuffer.texels[i];
      const AtlasPage& page = gbuffer.pages[t.page];
      double weight_sum = 0, sum[3] = {0, 0, 0}, variance_sum[3] = {0, 0, 0};
      std::fill(layer_sum.begin(), layer_sum.end(), 0.0);
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          const int x = int(t.x) + dx, y = int(t.y) + dy;
          if (x < 0 || y < 0 || x >= page.width || y >= page.height) continue;
          const uint32_t j = texel_at[page_first[t.page] + size_t(y) * size_t(page.width) + size_t(x)];
          if (j == kNone || estimate.texels[j].samples == 0) continue;
          const LiveTexel& u = gbuffer.texels[j];
          double w = texture_space_filter_weight(t.position, t.geometric_normal, t.world_texel_size, u.position,
                                                 u.geometric_normal, dx, dy, r);
          if (w <= 0) continue;
          float difference = 0, variances = 0;
          for (int c = 0; c < 3; ++c)
            difference += (indirect[j][c] - indirect[i][c]) * (indirect[j][c] - indirect[i][c]), variances += variance[i][c] + variance[j][c];
          w *= texture_space_filter_range_weight(difference, variances);
          if (w <= 0) continue;
          ++my_neighbours;
          weight_sum += w;
          for (int c = 0; c < 3; ++c) sum[c] += w * indirect[j][c], variance_sum[c] += w * w * variance[j][c];
          for (int k = 1; k < layers; ++k)
            for (size_t c = 0; c < 3; ++c)
              layer_sum[size_t(k) * 3 + c] += w * estimate.bounces[(size_t(k) * n + j) * 3 + c] / estimate.texels[j].samples;
        }
      // The texel itself always has weight 1 (same surface, offset 0), so weight_sum >= 1.
      double mean[3], variance_of_mean[3];
      for (int c = 0; c < 3; ++c) {
        mean[c] = a.direct[c] / a.samples + sum[c] / weight_sum;
        variance_of_mean[c] = variance_sum[c] / (weight_sum * weight_sum);
      }
      set_total_sums(out.texels[i], a.samples, mean, variance_of_mean);
      for (int k = 1; k < layers; ++k)
        for (size_t c = 0; c < 3; ++c)
          out.bounces[(size_t(k) * n + i) * 3 + c] = double(a.samples) * layer_sum[size_t(k) * 3 + c] / weight_sum;
      ++my_filtered;
    }
    filtered += my_filtered;
    neighbours += my_neighbours;
  }, 4096);
  if (report) {
    report->texels = filtered;
    report->mean_neighbours = filtered > 0 ? double(neighbours) / double(filtered) : 0.0;
    report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return out;
}

}  // namespace exitance
