// L2 spherical harmonics for C++ callers: RGB coefficient sets, projection, irradiance, deringing.
// The basis itself and the cosine-lobe factors are shared with the shaders (spherical_harmonics_basis.h).
#pragma once
#include <array>
#include <cmath>

#include "exitance/common/spherical_harmonics_basis.h"
#include "exitance/runtime/vec_math.h"

namespace exitance {

using ShBasis = std::array<float, kShCoefficients>;
using ShRgb = std::array<Vec3, kShCoefficients>;

// The basis (runtime/common/.../spherical_harmonics_basis.h, shared with the shaders) as an array.
inline ShBasis sh_basis(Vec3 d) {
  float y[kShCoefficients];
  sh_basis(d, y);
  ShBasis out;
  for (int i = 0; i < kShCoefficients; ++i) out[size_t(i)] = y[i];
  return out;
}

// Adds one quadrature/Monte Carlo term of the projection integral: radiance * Y(d) * weight, where
// weight is the solid angle the sample stands for (4*pi/N for N uniform sphere samples).
inline void sh_add_sample(ShRgb& sh, Vec3 direction, Vec3 radiance, float weight) {
  const ShBasis y = sh_basis(direction);
  for (int i = 0; i < kShCoefficients; ++i) sh[size_t(i)] += radiance * (y[size_t(i)] * weight);
}


// Irradiance over pi for a surface of normal n: convolution with the clamped cosine, whose
// band factors are pi, 2pi/3, pi/4 (Ramamoorthi & Hanrahan 2001), divided by pi.
inline Vec3 sh_irradiance_over_pi(const ShRgb& radiance, Vec3 n) {
  const ShBasis y = sh_basis(n);
  Vec3 e{0, 0, 0};
  for (int i = 0; i < kShCoefficients; ++i) e += radiance[i] * (sh_cosine_lobe_over_pi(sh_band(i)) * y[i]);
  return e;
}

// Optional deringing: a Hanning window over the bands, w_l = (1 + cos(pi l / width)) / 2 for
// l < width, 0 beyond. width = 3 keeps band 0, scales band 1 by 0.75 and band 2 by 0.25. Reduces
// negative lobes around bright sources at the cost of blur.
inline float sh_hanning_band_weight(int band, float width) {
  const float l = float(band);
  return l < width ? 0.5f * (1.0f + std::cos(3.14159265358979f * l / width)) : 0.0f;
}
inline void sh_apply_hanning_window(ShRgb& sh, float width) {
  for (int i = 0; i < kShCoefficients; ++i) sh[i] = sh[i] * sh_hanning_band_weight(sh_band(i), width);
}

}  // namespace exitance
