// SH projection and irradiance against closed forms (issue: probes). The projections use an exact
// quadrature (Gauss-Legendre in z, uniform in phi), so they must match to 1e-5.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "exitance/common/sampling.h"
#include "exitance/runtime/spherical_harmonics.h"

namespace exitance {
namespace {

// Gauss-Legendre nodes and weights on [a, b] (Newton iteration on P_n).
void gauss_legendre(int n, double a, double b, std::vector<double>& x, std::vector<double>& w) {
  x.resize(size_t(n));
  w.resize(size_t(n));
  for (int i = 0; i < n; ++i) {
    double z = std::cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 0;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1, p1 = 0;
      for (int k = 1; k <= n; ++k) {
        const double p2 = p1;
        p1 = p0;
        p0 = ((2 * k - 1) * z * p1 - (k - 1) * p2) / k;
      }
      dp = n * (z * p0 - p1) / (z * z - 1);
      const double step = p0 / dp;
      z -= step;
      if (std::fabs(step) < 1e-15) break;
    }
    x[size_t(i)] = 0.5 * (b - a) * z + 0.5 * (b + a);
    w[size_t(i)] = (b - a) / ((1 - z * z) * dp * dp);
  }
}

// Projects f over the sphere; the z range is split at 0 so clamped functions stay polynomial.
// Sums in double so the check measures the basis, not float accumulation over 2048 terms.
ShRgb project(const std::function<float(Vec3)>& f) {
  std::array<double, 9> sum{};
  const int phi_steps = 64;
  for (auto [a, b] : {std::pair{-1.0, 0.0}, std::pair{0.0, 1.0}}) {
    std::vector<double> zs, ws;
    gauss_legendre(16, a, b, zs, ws);
    for (size_t i = 0; i < zs.size(); ++i)
      for (int j = 0; j < phi_steps; ++j) {
        const double phi = 2 * M_PI * (j + 0.5) / phi_steps, r = std::sqrt(1 - zs[i] * zs[i]);
        const Vec3 d{float(r * std::cos(phi)), float(r * std::sin(phi)), float(zs[i])};
        const ShBasis y = sh_basis(d);
        for (int k = 0; k < 9; ++k) sum[size_t(k)] += double(f(d)) * y[size_t(k)] * ws[i] * 2 * M_PI / phi_steps;
      }
  }
  ShRgb sh{};
  for (int k = 0; k < 9; ++k) sh[size_t(k)] = Vec3{float(sum[size_t(k)]), float(sum[size_t(k)]), float(sum[size_t(k)])};
  return sh;
}

void expect_coefficients(const ShRgb& sh, const std::array<double, 9>& expected) {
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(sh[size_t(i)].x, expected[size_t(i)], 1e-5) << "coefficient " << i;
}

TEST(SphericalHarmonics, ConstantRadiance) {
  expect_coefficients(project([](Vec3) { return 1.0f; }), {2 * std::sqrt(M_PI), 0, 0, 0, 0, 0, 0, 0, 0});
}

TEST(SphericalHarmonics, LinearRadiance) {
  const double c1 = 2 * std::sqrt(M_PI / 3);  // integral of z * Y10 over the sphere
  expect_coefficients(project([](Vec3 d) { return d.z; }), {0, 0, c1, 0, 0, 0, 0, 0, 0});
  expect_coefficients(project([](Vec3 d) { return d.x; }), {0, 0, 0, c1, 0, 0, 0, 0, 0});
  expect_coefficients(project([](Vec3 d) { return d.y; }), {0, c1, 0, 0, 0, 0, 0, 0, 0});
}

TEST(SphericalHarmonics, ClampedCosine) {
  // max(0, z): Y00 * pi, Y10 * 2pi/3, Y20 * pi/2 (all other bands of a z-symmetric lobe vanish).
  expect_coefficients(project([](Vec3 d) { return std::max(0.0f, d.z); }),
                      {0.282094792 * M_PI, 0, 0.488602512 * 2 * M_PI / 3, 0, 0, 0, 0.315391565 * M_PI / 2, 0, 0});
}

TEST(SphericalHarmonics, ConstantSkyIrradianceIsPiL) {
  const ShRgb sh = project([](Vec3) { return 0.75f; });
  for (Vec3 n : {Vec3{0, 1, 0}, Vec3{1, 0, 0}, normalize(Vec3{0.3f, -0.5f, 0.8f})})
    EXPECT_NEAR(sh_irradiance_over_pi(sh, n).x, 0.75, 1e-5);  // E = pi L, stored as E/pi = L
}

TEST(SphericalHarmonics, IrradianceOfAHemisphereSky) {
  // Radiance 1 from z > 0 only: exact E/pi at the pole is 1 and at the equator 1/2; L2 gets the
  // pole within its known truncation error and the equator exactly (odd bands vanish there).
  const ShRgb sh = project([](Vec3 d) { return d.z > 0 ? 1.0f : 0.0f; });
  EXPECT_NEAR(sh_irradiance_over_pi(sh, {1, 0, 0}).x, 0.5, 1e-5);
  EXPECT_NEAR(sh_irradiance_over_pi(sh, {0, 0, 1}).x, 1.0, 0.01);
}

TEST(SphericalHarmonics, HanningWindowScalesBands) {
  ShRgb sh;
  for (auto& c : sh) c = {1, 1, 1};
  sh_apply_hanning_window(sh, 3.0f);
  EXPECT_FLOAT_EQ(sh[0].x, 1.0f);
  EXPECT_NEAR(sh[2].x, 0.75f, 1e-6f);
  EXPECT_NEAR(sh[6].x, 0.25f, 1e-6f);
}

TEST(SphericalHarmonics, MonteCarloProjectionConverges) {
  // What a probe does: uniform sphere samples weighted 4pi/N reproduce the clamped cosine.
  ShRgb sh{};
  const int n = 1 << 18;
  for (int i = 0; i < n; ++i) {
    // Stratified in z and phi so the estimate converges fast and deterministically.
    const float u1 = (float(i % 512) + 0.5f) / 512.0f, u2 = (float(i / 512) + 0.5f) / 512.0f;
    const Vec3 d = uniform_sphere(u1, u2);
    const float v = std::max(0.0f, d.z);
    sh_add_sample(sh, d, {v, v, v}, 4.0f * kPi / float(n));
  }
  EXPECT_NEAR(sh[0].x, 0.282094792 * M_PI, 1e-3);
  EXPECT_NEAR(sh[2].x, 0.488602512 * 2 * M_PI / 3, 1e-3);
}

}  // namespace
}  // namespace exitance
