#include "exitance/runtime/environment_sampler.h"

#include <cmath>

#include "exitance/common/sampling.h"

namespace exitance {

Vec2 direction_to_equirect(Vec3 d) {
  const float u = 0.5f + std::atan2(d.x, -d.z) / (2.0f * kPi);
  const float v = std::acos(std::clamp(d.y, -1.0f, 1.0f)) / kPi;
  return {u, v};
}

Vec3 equirect_to_direction(Vec2 uv) {
  const float phi = (uv.x - 0.5f) * 2.0f * kPi, theta = uv.y * kPi;
  const float s = std::sin(theta);
  return {s * std::sin(phi), std::cos(theta), -s * std::cos(phi)};
}

EnvironmentSampler::EnvironmentSampler(const Texture& environment) : texture_(&environment) {
  const int w = environment.width, h = environment.height;
  std::vector<double> row_weights(size_t(h), 0.0);
  rows_.reserve(size_t(h));
  for (int y = 0; y < h; ++y) {
    const double sin_theta = std::sin(kPi * (double(y) + 0.5) / double(h));
    std::vector<double> weights(static_cast<size_t>(w), 0.0);
    for (int x = 0; x < w; ++x) {
      const size_t i = (size_t(y) * size_t(w) + size_t(x)) * 3;
      weights[size_t(x)] = luminance({environment.rgb[i], environment.rgb[i + 1], environment.rgb[i + 2]}) * sin_theta;
    }
    rows_.emplace_back(weights);
    row_weights[size_t(y)] = rows_.back().total();
  }
  marginal_ = Distribution1D(row_weights);
}

Vec3 EnvironmentSampler::radiance(Vec3 direction) const {
  const Vec2 uv = direction_to_equirect(direction);
  const int x = std::clamp(int(uv.x * float(texture_->width)), 0, texture_->width - 1);
  const int y = std::clamp(int(uv.y * float(texture_->height)), 0, texture_->height - 1);
  const size_t i = (size_t(y) * size_t(texture_->width) + size_t(x)) * 3;
  return {texture_->rgb[i], texture_->rgb[i + 1], texture_->rgb[i + 2]};
}

Vec3 EnvironmentSampler::sample(float u1, float u2, float& pdf_out) const {
  float ru = 0, rv = 0;
  const size_t y = marginal_.sample(u1, &rv);
  const size_t x = rows_[y].sample(u2, &ru);
  const Vec2 uv{(float(x) + ru) / float(texture_->width), (float(y) + rv) / float(texture_->height)};
  const Vec3 direction = equirect_to_direction(uv);
  pdf_out = pdf(direction);
  return direction;
}

float EnvironmentSampler::pdf(Vec3 direction) const {
  const Vec2 uv = direction_to_equirect(direction);
  const int x = std::clamp(int(uv.x * float(texture_->width)), 0, texture_->width - 1);
  const int y = std::clamp(int(uv.y * float(texture_->height)), 0, texture_->height - 1);
  // Jacobian of the equirectangular map at the direction's own latitude (not the row centre).
  const double sin_theta = std::sqrt(std::max(0.0, 1.0 - double(direction.y) * double(direction.y)));
  if (sin_theta <= 1e-7) return 0.0f;
  const double pdf_uv = double(marginal_.pmf(size_t(y))) * double(rows_[size_t(y)].pmf(size_t(x))) *
                        double(texture_->width) * double(texture_->height);
  return float(pdf_uv / (2.0 * kPi * kPi * sin_theta));
}

}  // namespace exitance
