// Directional (L1 SH) lightmaps (issue 14, bake --directional sh1) against closed forms: the CPU
// reference's L1 = (1 / 2 pi) * integral of L(w) w dw per texel (docs/bundle.md, "Directional
// layers") for a uniform sky, a directional light and a uniform emitting square (Arvo's vector
// irradiance). Each comparison is a z-test of a region's mean residual (estimate - exact) within 4
// standard errors taken from the sample variance of the per-texel residuals, never a tuned tolerance.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "exitance/common/sampling.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "support/analytic_scenes.h"

namespace exitance {
namespace {

using testing::AnalyticScene;

constexpr double kZLimit = 4.0;

struct RegionCheck {
  double mean_residual = 0;
  double standard_error = 0;
  double mean_exact = 0;
};

// Mean and standard error of (estimate - exact) over the texels of a region.
RegionCheck residuals(const std::vector<double>& estimate, const std::vector<double>& exact) {
  RegionCheck r;
  const double n = double(estimate.size());
  for (size_t i = 0; i < estimate.size(); ++i) r.mean_residual += (estimate[i] - exact[i]) / n, r.mean_exact += exact[i] / n;
  double squares = 0;
  for (size_t i = 0; i < estimate.size(); ++i) squares += std::pow(estimate[i] - exact[i] - r.mean_residual, 2);
  r.standard_error = std::sqrt(squares / (n - 1) / n);
  return r;
}

// `exact_l1(texel)` gives the L1 vector of a unit-colour source; channel c scales by colour[c].
// Regions: consecutive groups of `region_size` texels. Also checks RGB against a.exact.
template <typename ExactL1>
void expect_l1_matches(const AnalyticScene& a, const LightmapEstimate& estimate, ExactL1 exact_l1, size_t region_size,
                       const char* what) {
  ASSERT_TRUE(estimate.has_sh1());
  EXPECT_EQ(estimate.nonfinite_samples, 0u);
  const size_t texels = a.gbuffer.texels.size();
  for (size_t begin = 0; begin + region_size <= texels; begin += region_size)
    for (int c = 0; c < 3; ++c) {
      // axis 3 stands for the RGB layer E/pi.
      for (int axis = 0; axis < 4; ++axis) {
        std::vector<double> est, exact;
        for (size_t i = begin; i < begin + region_size; ++i) {
          est.push_back(axis < 3 ? estimate.mean_sh1(axis, i)[c] : estimate.mean_total(i)[c]);
          exact.push_back((axis < 3 ? double(exact_l1(i)[axis]) : a.exact[i]) * a.colour[c]);
        }
        const RegionCheck r = residuals(est, exact);
        const double rounding = 1e-5 * std::fabs(r.mean_exact) + 1e-7;
        SCOPED_TRACE(::testing::Message() << what << " texels " << begin << "+" << region_size << " channel " << c
                                          << (axis < 3 ? " L1 axis " : " E/pi ") << (axis < 3 ? axis : 0)
                                          << ": exact " << r.mean_exact << " residual " << r.mean_residual << " SE "
                                          << r.standard_error);
        EXPECT_LE(std::fabs(r.mean_residual), kZLimit * r.standard_error + rounding);
        if (c == 0 && begin == 0)
          std::printf("[sh1] %-28s %s%d exact %.6g residual %+.3g SE %.3g\n", what, axis < 3 ? "L1." : "E/pi",
                      axis < 3 ? axis : 0, r.mean_exact, r.mean_residual, r.standard_error);
      }
    }
}

LightmapEstimate bake_directional(const AnalyticScene& a, uint32_t spp) {
  IntegratorSettings settings;
  settings.spp = spp;
  settings.seed = 11;
  settings.directional = DirectionalMode::Sh1;
  return CpuReferenceIntegrator(a.scene).bake(a.gbuffer, settings);
}

// A uniform sky L over the hemisphere: E/pi = L, L1 = L n0 / 2 (n0 = +y).
TEST(DirectionalSh1, UniformSkyGivesHalfTheNormal) {
  const AnalyticScene a = testing::plane_under_constant_sky();
  const LightmapEstimate estimate = bake_directional(a, 256);
  expect_l1_matches(a, estimate, [](size_t) { return Vec3{0, 0.5f, 0}; }, 16, "uniform sky");
}

// A directional light of irradiance E (normal to it) from direction l: L1 = E l / (2 pi).
TEST(DirectionalSh1, DirectionalLightPointsAtTheLight) {
  const AnalyticScene a = testing::directional_light_on_plane();
  const LightmapEstimate estimate = bake_directional(a, 64);
  const Vec3 l = -a.scene.lights[0].direction;
  expect_l1_matches(a, estimate, [&](size_t) { return l * float(0.5 / kPi); }, 16, "directional light");
}

// Arvo's vector irradiance of a polygon seen from p (vertices in order): 1/2 sum theta_i n_i.
Vec3 vector_irradiance(Vec3 p, const std::vector<Vec3>& polygon) {
  double phi[3] = {0, 0, 0};
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Vec3 a = normalize(polygon[i] - p), b = normalize(polygon[(i + 1) % polygon.size()] - p);
    const double theta = std::acos(std::clamp(double(dot(a, b)), -1.0, 1.0));
    const Vec3 n = normalize(cross(a, b));
    for (int k = 0; k < 3; ++k) phi[k] += 0.5 * theta * n[k];
  }
  return {float(phi[0]), float(phi[1]), float(phi[2])};
}

// A uniform emitting square of radiance Le: L1 = Le Phi / (2 pi), Phi oriented towards the square
// (Phi . n0 / pi is then the point's form factor, which the test checks too).
TEST(DirectionalSh1, EmittingSquareFollowsVectorIrradiance) {
  const AnalyticScene a = testing::two_parallel_unit_squares();
  const std::vector<Vec3> square = {{0, 1, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}};
  std::vector<Vec3> exact(a.gbuffer.texels.size());
  for (size_t i = 0; i < exact.size(); ++i) {
    Vec3 phi = vector_irradiance(a.gbuffer.texels[i].position, square);
    if (phi.y < 0) phi = -phi;  // towards the square, above the receiver
    ASSERT_NEAR(phi.y / kPi, a.exact[i], 1e-5) << "vector irradiance against the form factor, texel " << i;
    exact[i] = phi * float(0.5 / kPi);
  }
  const LightmapEstimate estimate = bake_directional(a, 256);
  expect_l1_matches(a, estimate, [&](size_t i) { return exact[i]; }, 16, "emitting square");
}

// Off: no L1 sums at all.
TEST(DirectionalSh1, OffKeepsNoSums) {
  const AnalyticScene a = testing::plane_under_constant_sky();
  IntegratorSettings settings;
  settings.spp = 4;
  EXPECT_FALSE(CpuReferenceIntegrator(a.scene).bake(a.gbuffer, settings).has_sh1());
}

}  // namespace
}  // namespace exitance
