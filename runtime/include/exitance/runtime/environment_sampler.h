// Importance sampling of an equirectangular sky by luminance x sin(theta): builds the CDFs that
// runtime/common/.../environment_map.h samples (the same math the Vulkan kernels run, over the same
// CDFs, which the GPU scene uploads from here).
// Mapping (documented in docs/cli.md): u = 0.5 + atan2(x, -z) / 2pi, v = acos(y) / pi, row 0 = +Y.
#pragma once
#include <cstdint>
#include <vector>

#include "exitance/common/environment_map.h"
#include "exitance/runtime/scene.h"

namespace exitance {

class EnvironmentSampler {
 public:
  EnvironmentSampler() = default;
  explicit EnvironmentSampler(const Texture& environment);
  bool enabled() const { return enabled_; }
  // Radiance seen along `direction` (nearest texel: the pdf below is exact for it).
  Vec3 radiance(Vec3 direction) const;
  // Samples a direction; returns its solid-angle pdf (0 if the sample is unusable).
  Vec3 sample(float u1, float u2, float& pdf) const;
  float pdf(Vec3 direction) const;
  // The integral of the map's luminance over the sphere (texels by their solid angle): the sky's
  // power per unit of area across its directions, which starting light subpaths there weighs by.
  double luminance_integral() const { return luminance_integral_; }

  // What the GPU reads (enabled only): the image, width * height * 3 floats (row 0 = +Y), the
  // marginal CDF over rows (height + 1) and the rows' conditional CDFs (height * (width + 1)).
  uint32_t width() const { return uint32_t(texture_->width); }
  uint32_t height() const { return uint32_t(texture_->height); }
  const std::vector<float>& texels() const { return texture_->rgb; }
  const std::vector<double>& marginal_cdf() const { return marginal_cdf_; }
  const std::vector<double>& row_cdfs() const { return row_cdfs_; }

 private:
  const Texture* texture_ = nullptr;
  bool enabled_ = false;
  double luminance_integral_ = 0;
  std::vector<double> marginal_cdf_;
  std::vector<double> row_cdfs_;
};

}  // namespace exitance
