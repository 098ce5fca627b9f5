#include "exitance/runtime/core/adaptive_sampling_plan.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace exitance {
namespace {

// Texel index per atlas pixel of each page (-1 where no live texel), to find a texel's neighbours.
std::vector<std::vector<int64_t>> texel_index_per_page(const TexelGBuffer& gbuffer) {
  std::vector<std::vector<int64_t>> index(gbuffer.pages.size());
  for (size_t p = 0; p < gbuffer.pages.size(); ++p)
    index[p].assign(size_t(gbuffer.pages[p].width) * size_t(gbuffer.pages[p].height), -1);
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    const LiveTexel& t = gbuffer.texels[i];
    if (t.page < index.size() && t.x < uint32_t(gbuffer.pages[t.page].width) && t.y < uint32_t(gbuffer.pages[t.page].height))
      index[t.page][size_t(t.y) * size_t(gbuffer.pages[t.page].width) + t.x] = int64_t(i);
  }
  return index;
}

// The pilot samples of the texels around texel `i` (same page, same instance), not its own.
TexelSampleSums neighbourhood_of(const TexelGBuffer& gbuffer, const std::vector<std::vector<int64_t>>& index,
                                 const std::vector<TexelSampleSums>& pilot, size_t i, int radius) {
  TexelSampleSums sums;
  const LiveTexel& t = gbuffer.texels[i];
  if (t.page >= index.size()) return sums;
  const int width = gbuffer.pages[t.page].width, height = gbuffer.pages[t.page].height;
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx) {
      const int x = int(t.x) + dx, y = int(t.y) + dy;
      if ((dx == 0 && dy == 0) || x < 0 || y < 0 || x >= width || y >= height) continue;
      const int64_t j = index[t.page][size_t(y) * size_t(width) + size_t(x)];
      if (j < 0 || gbuffer.texels[size_t(j)].instance != t.instance) continue;
      const TexelSampleSums& s = pilot[size_t(j)];
      sums.samples += s.samples, sums.rays += s.rays, sums.sum += s.sum, sums.sum_squared += s.sum_squared;
    }
  return sums;
}

constexpr float kUnknown = -1.0f;

}  // namespace

AdaptivePlan plan_adaptive_rates(const TexelGBuffer& gbuffer, const std::vector<TexelSampleSums>& pilot,
                                 const AdaptivePlanSettings& settings) {
  const size_t texel_count = gbuffer.texels.size();
  AdaptivePlan plan;
  plan.rate.assign(texel_count, 1.0f);
  plan.relative_deviation.assign(texel_count, kUnknown);
  plan.cost.assign(texel_count, 1.0f);
  if (texel_count == 0 || pilot.size() != texel_count) return plan;

  // The error floor: a fraction of the scene's mean E/pi (mean over texels of their pilot means).
  double mean_sum = 0;
  size_t with_samples = 0;
  for (const TexelSampleSums& s : pilot)
    if (s.samples) mean_sum += s.sum / s.samples, ++with_samples;
  const double scene_mean = with_samples ? mean_sum / double(with_samples) : 0.0;
  plan.epsilon = scene_mean > 0 ? settings.floor_fraction * scene_mean : std::numeric_limits<double>::min();

  const std::vector<std::vector<int64_t>> index = texel_index_per_page(gbuffer);
  double deviation_sum = 0;
  size_t known = 0;
  for (size_t i = 0; i < texel_count; ++i) {
    const TexelSampleSums n = neighbourhood_of(gbuffer, index, pilot, i, std::max(0, settings.neighbour_radius));
    if (n.samples < 2) continue;
    plan.cost[i] = std::max(1.0f, float(double(n.rays) / n.samples));
    const double mean = n.sum / n.samples;
    const double variance = std::max(0.0, n.sum_squared / n.samples - mean * mean) * n.samples / (n.samples - 1.0);
    if (!(variance > 0) && !(mean > 0)) continue;  // no light seen yet: unknown, not converged
    if (!std::isfinite(variance) || !std::isfinite(mean)) continue;
    const float deviation = float(std::sqrt(variance) / (std::max(mean, 0.0) + plan.epsilon));
    plan.relative_deviation[i] = deviation;
    deviation_sum += deviation;
    ++known;
  }
  const float mean_deviation = known ? float(deviation_sum / double(known)) : 1.0f;
  for (float& d : plan.relative_deviation)
    if (d == kUnknown) d = mean_deviation, ++plan.without_evidence;

  // Rates proportional to the deviation, clamped around the mean and renormalized to a mean of 1.
  if (!(mean_deviation > 0)) return plan;
  double mean_cost = 0;
  for (float c : plan.cost) mean_cost += c;
  mean_cost /= double(texel_count);
  for (size_t i = 0; i < texel_count; ++i)
    plan.rate[i] = float(plan.relative_deviation[i] / mean_deviation * std::sqrt(mean_cost / plan.cost[i]));
  for (int round = 0; round < 4; ++round) {
    double sum = 0;
    for (float& rate : plan.rate) {
      rate = std::clamp(rate, float(settings.lowest_rate), float(settings.highest_rate));
      sum += rate;
    }
    const double scale = double(texel_count) / sum;
    for (float& rate : plan.rate) rate = float(rate * scale);
  }
  return plan;
}

uint32_t samples_for_target(float relative_deviation, double target, uint32_t least, uint32_t most) {
  most = std::max(least, most);
  if (!(target > 0)) return most;
  const double n = std::ceil(double(relative_deviation) * double(relative_deviation) / (target * target));
  if (!(n < double(most))) return most;
  return std::max(least, uint32_t(n));
}

}  // namespace exitance
