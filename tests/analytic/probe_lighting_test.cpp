// Closed-form checks of the CPU reference's light probes (DESIGN §6.1): incident radiance projected
// to L2 SH. The standard error comes from independent repeats (different seeds), and each check
// is a z-test within 4 SE plus a bound on the SE so a vague estimate cannot pass.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "exitance/common/sampling.h"
#include "support/analytic_scenes.h"
#include "support/independent_estimates.h"

namespace exitance {
namespace {

constexpr double kZLimit = 4.0;
constexpr int kRepeats = 16;

using RepeatedValue = testing::MeanAndError;

// Runs `repeats` probe bakes with seeds 1..repeats and summarises quantity(estimate) over them.
RepeatedValue repeat_probe_bake(const Scene& scene, const std::vector<Vec3>& probes, uint32_t spp,
                                const std::function<double(const ProbeEstimate&)>& quantity) {
  const CpuReferenceIntegrator integrator(scene);
  std::vector<double> values;
  for (int r = 0; r < kRepeats; ++r) {
    IntegratorSettings settings;
    settings.spp = spp;
    settings.seed = uint64_t(r + 1);
    const ProbeEstimate estimate = integrator.bake_probes(probes, settings);
    EXPECT_EQ(estimate.nonfinite_samples, 0u);
    values.push_back(quantity(estimate));
  }
  return testing::mean_and_standard_error(values);
}

void expect_close(const RepeatedValue& v, double exact, double max_relative_se, const char* what) {
  SCOPED_TRACE(::testing::Message() << what << ": estimate " << v.mean << " exact " << exact << " SE "
                                    << v.standard_error);
  EXPECT_LE(std::fabs(v.mean - exact), kZLimit * v.standard_error + 1e-5 * std::fabs(exact) + 1e-9);
  EXPECT_LE(v.standard_error, max_relative_se * std::fabs(exact) + 1e-9) << "standard error implausibly large";
  std::printf("[probes] %-40s exact %.6g estimate %.6g SE %.3g z %+.2f\n", what, exact, v.mean, v.standard_error,
              v.standard_error > 0 ? (v.mean - exact) / v.standard_error : 0.0);
}

// In the white furnace every probe sees radiance Le/(1-rho) from every direction, so E/pi for any
// normal is Le/(1-rho), and bands 1 and 2 vanish.
TEST(ProbeLighting, WhiteFurnaceProbesReadLeOverOneMinusRho) {
  const float albedo = 0.5f;
  const testing::AnalyticScene a = testing::white_furnace(albedo);
  const std::vector<Vec3> probes = {{0.5f, 0.5f, 0.5f}, {0.2f, 0.8f, 0.3f}, {0.9f, 0.1f, 0.6f}};
  const Vec3 normals[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (size_t p = 0; p < probes.size(); ++p) {
    for (const Vec3& n : normals) {
      const auto v = repeat_probe_bake(a.scene, {probes[p]}, 512, [&](const ProbeEstimate& e) {
        return double(sh_irradiance_over_pi(e.mean(0), n)[0]);
      });
      expect_close(v, a.colour[0] / (1.0 - albedo), 0.01, "furnace probe E/pi");
    }
    const auto band1 = repeat_probe_bake(a.scene, {probes[p]}, 512, [](const ProbeEstimate& e) {
      return double(e.mean(0)[2][1]);  // Y10 of the green channel
    });
    EXPECT_LE(std::fabs(band1.mean), kZLimit * band1.standard_error + 1e-6);
  }
}

// A probe above a black plane (albedo 0, so only the sky lights it) under a constant sky L: the
// incident radiance is L over the upper hemisphere, 0 below. Its L2 projection is exact for the up
// normal: c00 = L sqrt(pi), c1-1 (y) = L 0.4886 pi, E/pi(up) = L and E/pi(down) = 0.
TEST(ProbeLighting, ProbeAboveBlackPlaneUnderConstantSky) {
  Scene scene;
  const float half = 1000.0f;  // directions below the horizon that miss the plane: ~1e-3 sr, negligible
  testing::add_quad(scene, {-half, 0, half}, {2 * half, 0, 0}, {0, 0, -2 * half},
                    testing::add_material(scene, {0, 0, 0}));
  scene.sky.constant = {0.5f, 1.0f, 2.0f};
  const std::vector<Vec3> probe = {{0.0f, 1.0f, 0.0f}};
  const auto c00 = repeat_probe_bake(scene, probe, 256, [](const ProbeEstimate& e) { return double(e.mean(0)[0][1]); });
  expect_close(c00, 1.0 * std::sqrt(kPi), 0.01, "c00 above black plane");
  const auto c1 = repeat_probe_bake(scene, probe, 256, [](const ProbeEstimate& e) { return double(e.mean(0)[1][1]); });
  expect_close(c1, 1.0 * 0.488602512 * kPi, 0.01, "c1-1 above black plane");
  const auto up = repeat_probe_bake(scene, probe, 256, [](const ProbeEstimate& e) {
    return double(sh_irradiance_over_pi(e.mean(0), {0, 1, 0})[2]);
  });
  expect_close(up, 2.0, 0.01, "E/pi up above black plane");
}

// A probe outside a closed box of single-sided inward faces sees only back faces: every ray says
// so (the signal probe placement uses to detect probes inside geometry), and no light arrives.
TEST(ProbeLighting, ProbeSeeingOnlyBackFacesCountsThemAll) {
  const testing::AnalyticScene a = testing::white_furnace(0.5f);
  const CpuReferenceIntegrator integrator(a.scene);
  IntegratorSettings settings;
  settings.spp = 64;
  // Outside the box every direction toward it hits an outward-facing back face; the rest miss (black sky).
  const ProbeEstimate inside_out = integrator.bake_probes({{0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, -0.001f}}, settings);
  EXPECT_EQ(inside_out.backface_hits[0], 0u);
  EXPECT_GT(inside_out.backface_hits[1], 20u);  // about half the sphere
  EXPECT_LT(inside_out.backface_hits[1], 44u);
  for (int i = 0; i < kShCoefficients; ++i) EXPECT_EQ(inside_out.mean(1)[i][0], 0.0f);
}

}  // namespace
}  // namespace exitance
