#include "published_probes.h"

#include <algorithm>
#include <cmath>

#include "exitance/common/publishing_rule.h"
#include "exitance/runtime/spherical_harmonics.h"

namespace exitance {

bool probe_shows_refreshed(const KeptProbe& kept, const ProbeEstimate& refreshed, size_t k, uint32_t switch_samples) {
  const uint32_t n = refreshed.samples[k];
  // Without squared sums (no variance to compare) as for a kept value of unknown variance.
  if (n == 0 || k >= refreshed.l0_square_sum.size()) return publish_probe_refreshed(n, switch_samples, kept.samples, -1, 0, 0, false);
  double difference_squared = 0;
  bool all_zero = true;
  for (size_t c = 0; c < 3; ++c) {
    const double d = refreshed.sh_sum[k][c] / n - double(kept.sh[c]);  // L0: the dering window keeps band 0
    difference_squared += d * d;
    all_zero = all_zero && refreshed.sh_sum[k][c] == 0 && refreshed.l0_square_sum[k][c] == 0;
  }
  return publish_probe_refreshed(n, switch_samples, kept.samples, kept.variance, difference_squared, refreshed.l0_variance_of_mean(k),
                                 all_zero);
}

std::array<float, 3> probe_band_weights(float dering_window) {
  std::array<float, 3> weight{1.0f, 1.0f, 1.0f};
  if (dering_window > 0)
    for (int band = 0; band < 3; ++band) weight[size_t(band)] = sh_hanning_band_weight(band, dering_window);
  return weight;
}

uint32_t probe_change_choice(const KeptProbe& base, const ProbeEstimate& change, size_t k) {
  const uint32_t n = k < change.samples.size() ? change.samples[k] : 0;
  double squared = 0;
  if (n > 0)
    for (size_t c = 0; c < 3; ++c) {
      const double d = change.sh_sum[k][c] / n;
      squared += d * d;
    }
  return publish_after_change(base.samples, n, squared, change.l0_variance_of_mean(k));
}

KeptProbe probe_base_plus_change(const KeptProbe& base, const ProbeEstimate& change, size_t k, const std::array<float, 3>& band_weight) {
  KeptProbe shown = base;
  const ShRgb mean = change.mean(k);
  for (size_t i = 0; i < 9; ++i)
    for (size_t c = 0; c < 3; ++c) {
      const float d = mean[i][int(c)] * band_weight[size_t(sh_band(int(i)))];
      const float sum = base.sh[i * 3 + c] + d;
      if (std::isfinite(sum)) shown.sh[i * 3 + c] = sum;
    }
  shown.variance = base.variance < 0 ? -1.0 : base.variance + change.l0_variance_of_mean(k);
  return shown;
}

void scale_kept_probes(std::vector<KeptProbe>& kept, const ProbeEstimate& layer, Vec4 factor, float dering_window) {
  for (size_t k = 0; k < kept.size() && k < layer.samples.size(); ++k) {
    if (layer.samples[k] == 0) continue;
    ShRgb mean = layer.mean(k);
    if (dering_window > 0) sh_apply_hanning_window(mean, dering_window);
    KeptProbe& probe = kept[k];
    const float f[3] = {factor.x, factor.y, factor.z};
    double before = 0, after = 0;
    for (size_t i = 0; i < 9; ++i)
      for (size_t c = 0; c < 3; ++c) {
        float& value = probe.sh[i * 3 + c];
        const float scaled = value + (f[c] - 1.0f) * mean[i][int(c)];
        if (i == 0) before += double(value) * value, after += double(scaled) * scaled;
        value = i == 0 ? std::max(scaled, 0.0f) : scaled;  // L0 is a sum of non-negative radiance
      }
    if (probe.variance > 0) probe.variance = before > 0 ? probe.variance * after / before : probe.variance;
  }
}

std::vector<uint32_t> probes_nearest_first(const std::vector<Vec3>& positions, const std::vector<Vec3>& points,
                                           const std::vector<WorldBox>& boxes, float near_floor, size_t* near) {
  if (near) *near = 0;
  if (points.empty() && boxes.empty()) return {};
  std::vector<float> distance(positions.size(), INFINITY);
  std::vector<uint8_t> near_flag(positions.size(), 1);  // 0: near (sorted first)
  for (size_t k = 0; k < positions.size(); ++k) {
    bool is_near = false;
    for (const Vec3& p : points) {
      const float d = dot(positions[k] - p, positions[k] - p);
      distance[k] = std::min(distance[k], d);
      is_near = is_near || d <= near_floor * near_floor;
    }
    for (const WorldBox& b : boxes) {
      const float d = b.distance_squared(positions[k]);
      const float r = std::max(2.0f * b.half_diagonal(), near_floor);
      distance[k] = std::min(distance[k], d);
      is_near = is_near || d <= r * r;
    }
    if (is_near && near) ++*near;
    near_flag[k] = is_near ? 0 : 1;
  }
  std::vector<uint32_t> order(positions.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = uint32_t(k);
  // The near probes first (the first *near of the order), each part nearest first.
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return near_flag[a] != near_flag[b] ? near_flag[a] < near_flag[b] : distance[a] < distance[b];
  });
  return order;
}

}  // namespace exitance
