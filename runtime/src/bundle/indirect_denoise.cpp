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
    struct Neighbour {
      uint32_t texel;
      double w, u, v;  // its weight, its offset in the texel's plane (texture_space_filter_plane_offset)
    };
    std::vector<Neighbour> window;
    window.reserve(size_t(2 * r + 1) * size_t(2 * r + 1));
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
            difference += (indirect[j][c] - indirect[i][c]) * (indirect[j][c] - indirect[i][c]), variances += texture_space_filter_range_variance(variance[i][c], variance[j][c]);
          w *= texture_space_filter_range_weight(difference, variances);
          if (w <= 0) continue;
          ++my_neighbours;
          const Vec2 offset = texture_space_filter_plane_offset(t.geometric_normal, u.position - t.position, t.world_texel_size);
          window.push_back({uint32_t(j), w, offset.x, offset.y});
        }
      // The linear fit's weights w_j (c0 + c1 u_j + c2 v_j) (texture_space_filter.h), or the
      // weighted mean's w_j where the window does not span the plane.
      double m00 = 0, m01 = 0, m02 = 0, m11 = 0, m12 = 0, m22 = 0;
      double fit_sum[3] = {0, 0, 0}, fit_u[3] = {0, 0, 0}, fit_v[3] = {0, 0, 0};
      double q00 = 0, q01 = 0, q02 = 0, q11 = 0, q12 = 0, q22 = 0;
      for (const Neighbour& q : window) {
        m00 += q.w, m01 += q.w * q.u, m02 += q.w * q.v;
        m11 += q.w * q.u * q.u, m12 += q.w * q.u * q.v, m22 += q.w * q.v * q.v;
        const double wv = q.w * q.w * (double(variance[q.texel][0]) + double(variance[q.texel][1]) + double(variance[q.texel][2]));
        q00 += wv, q01 += wv * q.u, q02 += wv * q.v;
        q11 += wv * q.u * q.u, q12 += wv * q.u * q.v, q22 += wv * q.v * q.v;
        for (int c = 0; c < 3; ++c) {
          fit_sum[c] += q.w * double(indirect[q.texel][c]);
          fit_u[c] += q.w * q.u * double(indirect[q.texel][c]);
          fit_v[c] += q.w * q.v * double(indirect[q.texel][c]);
        }
      }
      double c0 = 0, c1 = 0, c2 = 0;
      bool linear = texture_space_filter_linear_row(m00, m01, m02, m11, m12, m22, c0, c1, c2);
      // Indirect light is never negative: where the fit would be (extrapolated at a chart's corner
      // beside a steep change), the weighted mean, which cannot be, is used.
      double difference_squared = 0;
      for (int c = 0; c < 3; ++c) {
        const double fit = c0 * fit_sum[c] + c1 * fit_u[c] + c2 * fit_v[c];
        linear = linear && fit >= 0.0;
        difference_squared += (fit_sum[c] / m00 - fit) * (fit_sum[c] / m00 - fit);
      }
      linear = linear && texture_space_filter_prefers_fit(difference_squared, m00, q00, q01, q02, q11, q12, q22, c0, c1, c2);
      if (linear)
        for (Neighbour& q : window) q.w *= c0 + c1 * q.u + c2 * q.v;
      for (const Neighbour& q : window) {
        const size_t j = q.texel;
        const double w = q.w;
        weight_sum += w;
        for (int c = 0; c < 3; ++c) sum[c] += w * indirect[j][c], variance_sum[c] += w * w * variance[j][c];
        for (int k = 1; k < layers; ++k)
          for (size_t c = 0; c < 3; ++c)
            layer_sum[size_t(k) * 3 + c] += w * estimate.bounces[(size_t(k) * n + j) * 3 + c] / estimate.texels[j].samples;
      }
      window.clear();
      // The texel itself always has weight 1 (same surface, offset 0), so the mean's weight_sum >= 1;
      // the fit's weights sum to 1 (to rounding).
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
