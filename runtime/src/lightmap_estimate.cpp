// LightmapEstimate's accessors: plain arithmetic on the sums, shared by every backend (and by
// the runtime library, which links no Embree), so they live apart from the CPU integrator.
#include <algorithm>

#include <cmath>

#include "exitance/common/publishing_rule.h"
#include "exitance/runtime/core/estimates.h"

namespace exitance {

void set_total_sums(TexelAccumulator& texel, uint32_t samples, const double mean[3], const double variance_of_mean[3]) {
  const double n = samples;
  texel.samples = samples;
  for (int c = 0; c < 3; ++c) {
    texel.total[c] = n * mean[c];
    texel.total_squared[c] = n * mean[c] * mean[c] + n * (n - 1) * variance_of_mean[c];
  }
}

Vec3 LightmapEstimate::mean_total(size_t texel) const {
  const TexelAccumulator& a = texels[texel];
  if (a.samples == 0) return {0, 0, 0};
  return {float(a.total[0] / a.samples), float(a.total[1] / a.samples), float(a.total[2] / a.samples)};
}

Vec3 LightmapEstimate::mean_direct(size_t texel) const {
  const TexelAccumulator& a = texels[texel];
  if (a.samples == 0) return {0, 0, 0};
  return {float(a.direct[0] / a.samples), float(a.direct[1] / a.samples), float(a.direct[2] / a.samples)};
}

Vec3 LightmapEstimate::mean_bounce(int bounce, size_t texel) const {
  const TexelAccumulator& a = texels[texel];
  if (a.samples == 0 || bounce < 0 || bounce >= recorded_bounces) return {0, 0, 0};
  const size_t base = (size_t(bounce) * texels.size() + texel) * 3;
  return {float(bounces[base] / a.samples), float(bounces[base + 1] / a.samples), float(bounces[base + 2] / a.samples)};
}

Vec3 LightmapEstimate::mean_sh1(int axis, size_t texel) const {
  const TexelAccumulator& a = texels[texel];
  if (sh1.empty() || a.samples == 0 || axis < 0 || axis > 2) return {0, 0, 0};
  const size_t base = (texel * 3 + size_t(axis)) * 3;
  return {float(sh1[base] / a.samples), float(sh1[base + 1] / a.samples), float(sh1[base + 2] / a.samples)};
}

Vec3 LightmapEstimate::variance_of_mean(size_t texel) const {
  const TexelAccumulator& a = texels[texel];
  if (a.samples < 2) return {0, 0, 0};
  Vec3 v;
  for (int c = 0; c < 3; ++c) v[c] = variance_of_mean_from_sums(a.total[c], a.total_squared[c], a.samples);
  return v;
}

bool LightmapEstimate::relative_error_below(size_t texel, double target) const {
  const float lum = luminance(mean_total(texel));
  const float standard_error = std::sqrt(luminance(variance_of_mean(texel)));
  // A texel that stayed black with no variance over 16 samples or more (inside geometry) has no
  // relative error left to reduce: met (0/0 would keep a target-error run going forever).
  if (!(lum > 0)) return standard_error == 0 && texels[texel].samples >= 16;
  return standard_error <= target * lum;
}

double LightmapEstimate::mean_relative_standard_error() const {
  double sum = 0;
  size_t count = 0;
  for (size_t i = 0; i < texels.size(); ++i) {
    const float mean = luminance(mean_total(i));
    const float standard_error = std::sqrt(luminance(variance_of_mean(i)));
    if (mean > 0) sum += standard_error / mean, ++count;
  }
  return count ? sum / double(count) : 0.0;
}

double LightmapEstimate::error_floor() const {
  double sum = 0;
  size_t count = 0;
  for (size_t i = 0; i < texels.size(); ++i)
    if (texels[i].samples > 0) sum += luminance(mean_total(i)), ++count;
  return count ? kErrorFloorFraction * sum / double(count) : 0.0;
}

float LightmapEstimate::relative_standard_error(size_t texel, double floor) const {
  const double standard_error = std::sqrt(std::max(0.0f, luminance(variance_of_mean(texel))));
  const double denominator = std::max(0.0f, luminance(mean_total(texel))) + floor;
  return denominator > 0 ? float(standard_error / denominator) : 0.0f;
}

ShRgb ProbeEstimate::mean(size_t probe) const {
  ShRgb sh{};
  const uint32_t n = samples[probe];
  if (n == 0) return sh;
  for (int i = 0; i < kShCoefficients; ++i)
    for (int c = 0; c < 3; ++c) sh[i][c] = float(sh_sum[probe][size_t(i) * 3 + size_t(c)] / n);
  return sh;
}

double ProbeEstimate::l0_variance_of_mean(size_t probe) const {
  if (probe >= l0_square_sum.size()) return 0;
  double variance = 0;
  for (size_t c = 0; c < 3; ++c) variance += variance_of_mean_from_sums(sh_sum[probe][c], l0_square_sum[probe][c], samples[probe]);
  return variance;
}

Vec3 ProbeEstimate::mean_axis_irradiance_over_pi(size_t probe, int axis) const {
  if (probe >= axis_irradiance_sum.size() || samples[probe] == 0) return {0, 0, 0};
  const auto& a = axis_irradiance_sum[probe];
  const double n = samples[probe];
  return {float(a[size_t(axis) * 3] / n), float(a[size_t(axis) * 3 + 1] / n), float(a[size_t(axis) * 3 + 2] / n)};
}

}  // namespace exitance
