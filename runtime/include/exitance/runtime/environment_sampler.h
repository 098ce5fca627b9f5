// Importance sampling of an equirectangular sky by luminance x sin(theta).
// Mapping (documented in docs/cli.md): u = 0.5 + atan2(x, -z) / 2pi, v = acos(y) / pi, row 0 = +Y.
#pragma once
#include "exitance/runtime/distribution_1d.h"
#include "exitance/runtime/scene.h"

namespace exitance {

Vec2 direction_to_equirect(Vec3 direction);
Vec3 equirect_to_direction(Vec2 uv);

class EnvironmentSampler {
 public:
  EnvironmentSampler() = default;
  explicit EnvironmentSampler(const Texture& environment);
  bool enabled() const { return !marginal_.empty(); }
  // Radiance seen along `direction` (nearest texel: the pdf below is exact for it).
  Vec3 radiance(Vec3 direction) const;
  // Samples a direction; returns its solid-angle pdf (0 if the sample is unusable).
  Vec3 sample(float u1, float u2, float& pdf) const;
  float pdf(Vec3 direction) const;

 private:
  const Texture* texture_ = nullptr;
  Distribution1D marginal_;
  std::vector<Distribution1D> rows_;
};

}  // namespace exitance
