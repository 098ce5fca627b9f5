// Real L2 spherical harmonics (9 coefficients), Sloan's "Stupid Spherical Harmonics Tricks"
// ordering and constants: index = l*(l+1) + m, i.e. Y00, Y1-1, Y10, Y11, Y2-2, Y2-1, Y20, Y21, Y22.
// The basis is evaluated on world directions (x, y, z) as given (glTF: +Y up); probes.bin stores
// coefficients of incident radiance in this basis (DESIGN §4). Written in the subset of C++ that
// ports line by line to GLSL.
#pragma once
#include <array>
#include <cmath>

#include "exitance/runtime/vec_math.h"

namespace exitance {

constexpr int kShCoefficients = 9;
using ShBasis = std::array<float, kShCoefficients>;
using ShRgb = std::array<Vec3, kShCoefficients>;

inline ShBasis sh_basis(Vec3 d) {
  return {0.282094792f,
          0.488602512f * d.y,
          0.488602512f * d.z,
          0.488602512f * d.x,
          1.092548431f * d.x * d.y,
          1.092548431f * d.y * d.z,
          0.315391565f * (3.0f * d.z * d.z - 1.0f),
          1.092548431f * d.x * d.z,
          0.546274215f * (d.x * d.x - d.y * d.y)};
}

// Adds one quadrature/Monte Carlo term of the projection integral: radiance * Y(d) * weight, where
// weight is the solid angle the sample stands for (4*pi/N for N uniform sphere samples).
inline void sh_add_sample(ShRgb& sh, Vec3 direction, Vec3 radiance, float weight) {
  const ShBasis y = sh_basis(direction);
  for (int i = 0; i < kShCoefficients; ++i) sh[i] += radiance * (y[i] * weight);
}

inline int sh_band(int index) { return index == 0 ? 0 : (index < 4 ? 1 : 2); }

// Irradiance over pi for a surface of normal n: convolution with the clamped cosine, whose
// band factors are pi, 2pi/3, pi/4 (Ramamoorthi & Hanrahan 2001), divided by pi.
inline Vec3 sh_irradiance_over_pi(const ShRgb& radiance, Vec3 n) {
  constexpr float kBandFactorOverPi[3] = {1.0f, 2.0f / 3.0f, 0.25f};
  const ShBasis y = sh_basis(n);
  Vec3 e{0, 0, 0};
  for (int i = 0; i < kShCoefficients; ++i) e += radiance[i] * (kBandFactorOverPi[sh_band(i)] * y[i]);
  return e;
}

// Optional deringing: a Hanning window over the bands, w_l = (1 + cos(pi l / width)) / 2 for
// l < width, 0 beyond. width = 3 keeps band 0, scales band 1 by 0.75 and band 2 by 0.25. Reduces
// negative lobes around bright sources at the cost of blur.
inline void sh_apply_hanning_window(ShRgb& sh, float width) {
  for (int i = 0; i < kShCoefficients; ++i) {
    const float l = float(sh_band(i));
    const float w = l < width ? 0.5f * (1.0f + std::cos(3.14159265358979f * l / width)) : 0.0f;
    sh[i] = sh[i] * w;
  }
}

}  // namespace exitance
