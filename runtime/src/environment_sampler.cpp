#include "exitance/runtime/environment_sampler.h"

#include <cmath>

#include "exitance/runtime/distribution_1d.h"

namespace exitance {

EnvironmentSampler::EnvironmentSampler(const Texture& environment) : texture_(&environment) {
  const int w = environment.width, h = environment.height;
  std::vector<double> row_weights(size_t(h), 0.0);
  row_cdfs_.reserve(size_t(h) * (size_t(w) + 1));
  for (int y = 0; y < h; ++y) {
    const double sin_theta = std::sin(kPi * (double(y) + 0.5) / double(h));
    std::vector<double> weights(static_cast<size_t>(w), 0.0);
    for (int x = 0; x < w; ++x) {
      const size_t i = (size_t(y) * size_t(w) + size_t(x)) * 3;
      weights[size_t(x)] = luminance({environment.rgb[i], environment.rgb[i + 1], environment.rgb[i + 2]}) * sin_theta;
    }
    const Distribution1D row(weights);
    row_cdfs_.insert(row_cdfs_.end(), row.cdf().begin(), row.cdf().end());
    row_weights[size_t(y)] = row.total();
  }
  const Distribution1D marginal(row_weights);
  marginal_cdf_ = marginal.cdf();
  enabled_ = !marginal.empty();
  // Each texel spans (2 pi / w) x (pi / h) in (phi, theta), sin(theta) already in the weights.
  luminance_integral_ = marginal.total() * 2.0 * kPi * kPi / (double(w) * double(h));
}

Vec3 EnvironmentSampler::radiance(Vec3 direction) const {
  const size_t i = size_t(environment_texel(direction, width(), height())) * 3;
  return {texture_->rgb[i], texture_->rgb[i + 1], texture_->rgb[i + 2]};
}

Vec3 EnvironmentSampler::sample(float u1, float u2, float& pdf_out) const {
  const Vec3 direction = sample_environment_direction(marginal_cdf_.data(), row_cdfs_.data(), width(), height(), u1, u2);
  pdf_out = pdf(direction);
  return direction;
}

float EnvironmentSampler::pdf(Vec3 direction) const {
  return environment_direction_pdf(marginal_cdf_.data(), row_cdfs_.data(), width(), height(), direction);
}

}  // namespace exitance
