// Closed-form checks of the CPU reference integrator (DESIGN §6.1). Every comparison is a
// z-test of a texel group against the exact value within 4 standard errors estimated from the
// samples themselves, plus a bound on the standard error so a noisy estimator cannot pass by
// being vague. Deterministic cases (zero variance) must match to float rounding.
#include <gtest/gtest.h>

#include <cmath>

#include "exitance/common/sampling.h"
#include "support/analytic_scenes.h"

namespace exitance {
namespace {

using testing::AnalyticScene;
using testing::add_material;
using testing::add_quad;
using testing::compare_group;
using testing::grid_points;
using testing::texel_at;

constexpr double kZLimit = 4.0;

// `expected` holds per-texel values of a unit-colour light; channel c is scaled by colour[c].
void expect_group_matches(const LightmapEstimate& estimate, const std::vector<size_t>& texels,
                          const std::vector<double>& expected, Vec3 colour, double max_relative_se, const char* what) {
  for (int c = 0; c < 3; ++c) {
    std::vector<double> scaled(expected);
    for (double& v : scaled) v *= colour[c];
    const auto g = compare_group(estimate, texels, scaled, c);
    const double rounding = 1e-5 * std::fabs(g.expected) + 1e-9;
    SCOPED_TRACE(::testing::Message() << what << " channel " << c << ": estimate " << g.estimate << " expected "
                                      << g.expected << " SE " << g.standard_error << " z " << g.z());
    EXPECT_LE(std::fabs(g.estimate - g.expected), kZLimit * g.standard_error + rounding);
    EXPECT_LE(g.standard_error, max_relative_se * std::fabs(g.expected) + 1e-12) << "standard error implausibly large";
    std::printf("[analytic] %-34s ch%d exact %.6g estimate %.6g SE %.3g z %+.2f\n", what, c, g.expected, g.estimate,
                g.standard_error, g.z());
  }
}

std::vector<size_t> all_texels(const TexelGBuffer& g) {
  std::vector<size_t> v(g.texels.size());
  for (size_t i = 0; i < v.size(); ++i) v[i] = i;
  return v;
}

// `vertex_colour` >= 0: the material is white and COLOR_0 = vertex_colour on every corner carries
// the albedo instead (glTF: base colour x COLOR_0), so the closed form is Le / (1 - vertex_colour).
void run_furnace(float albedo, uint32_t spp, double max_relative_se, float vertex_colour = -1) {
  AnalyticScene a = testing::white_furnace(vertex_colour >= 0 ? 1.0f : albedo);
  if (vertex_colour >= 0) {
    a.scene.vertex_color.assign(a.scene.positions.size(), Vec3{vertex_colour, vertex_colour, vertex_colour});
    a.scene.vertex_alpha.assign(a.scene.positions.size(), 1.0f);
    a.exact.assign(a.gbuffer.texels.size(), 1.0 / (1.0 - vertex_colour));
    albedo = vertex_colour;
  }
  IntegratorSettings settings;
  settings.spp = spp;
  settings.seed = 7;
  const LightmapEstimate estimate = CpuReferenceIntegrator(a.scene).bake(a.gbuffer, settings);
  const std::vector<size_t> texels = all_texels(a.gbuffer);
  for (int c = 0; c < 3; ++c) {
    std::vector<double> expected(a.exact);
    for (double& v : expected) v *= a.colour[c];
    const auto g = compare_group(estimate, texels, expected, c);
    SCOPED_TRACE(::testing::Message() << "furnace albedo " << albedo << " channel " << c << " z " << g.z());
    EXPECT_LE(std::fabs(g.z()), kZLimit);
    EXPECT_GT(g.standard_error, 0.0);
    EXPECT_LE(g.standard_error, max_relative_se * g.expected);
    std::printf("[analytic] furnace rho=%.2f ch%d exact %.6g estimate %.6g SE %.3g z %+.2f\n", albedo, c, g.expected,
                g.estimate, g.standard_error, g.z());
  }
  EXPECT_EQ(estimate.nonfinite_samples, 0u);
}

TEST(AnalyticLighting, WhiteFurnaceAlbedoHalf) { run_furnace(0.5f, 256, 0.005); }
TEST(AnalyticLighting, WhiteFurnaceAlbedoPointNine) { run_furnace(0.9f, 512, 0.01); }
TEST(AnalyticLighting, WhiteFurnaceAlbedoFromVertexColours) { run_furnace(0.0f, 256, 0.005, 0.5f); }

TEST(AnalyticLighting, PlaneUnderConstantSky) {
  const AnalyticScene a = testing::plane_under_constant_sky();
  IntegratorSettings settings;
  settings.spp = 16;
  const LightmapEstimate estimate = CpuReferenceIntegrator(a.scene).bake(a.gbuffer, settings);
  for (size_t i = 0; i < a.gbuffer.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(estimate.mean_total(i)[c], a.colour[c], 1e-5 * a.colour[c]);
  expect_group_matches(estimate, all_texels(a.gbuffer), a.exact, a.colour, 1e-6, "plane under constant sky");
}

// An equirectangular sky that is bright below the horizon: importance sampling sends many
// samples there, MIS must still give exactly the upper hemisphere's radiance to an upward plane.
TEST(AnalyticLighting, PlaneUnderEnvironmentMapSky) {
  Scene scene;
  add_quad(scene, {-1, 0, 1}, {2, 0, 0}, {0, 0, -2}, add_material(scene, {0.0f, 0.0f, 0.0f}));
  const int w = 64, h = 32;
  scene.sky.environment.width = w;
  scene.sky.environment.height = h;
  scene.sky.environment.rgb.resize(size_t(w * h * 3));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c)
        scene.sky.environment.rgb[size_t((y * w + x) * 3 + c)] = y < h / 2 ? float(c + 1) : 100.0f;
  TexelGBuffer gbuffer;
  for (Vec2 p : grid_points(4, 0.1f)) gbuffer.texels.push_back(texel_at({2 * p.x - 1, 0, 2 * p.y - 1}, {0, 1, 0}));
  IntegratorSettings settings;
  settings.spp = 512;
  settings.seed = 3;
  const LightmapEstimate estimate = CpuReferenceIntegrator(scene).bake(gbuffer, settings);
  for (int c = 0; c < 3; ++c) {
    std::vector<double> expected(gbuffer.texels.size(), double(c + 1));
    const auto g = compare_group(estimate, all_texels(gbuffer), expected, c);
    EXPECT_LE(std::fabs(g.z()), kZLimit) << "channel " << c << " estimate " << g.estimate;
    EXPECT_LE(g.standard_error, 0.01 * g.expected);
    std::printf("[analytic] env-map sky upper hemisphere ch%d exact %.6g estimate %.6g SE %.3g z %+.2f\n", c,
                g.expected, g.estimate, g.standard_error, g.z());
  }
}

TEST(AnalyticLighting, PointLightInverseSquareAndCosine) {
  const AnalyticScene a = testing::point_light_over_plane();
  IntegratorSettings settings;
  settings.spp = 4;
  const LightmapEstimate estimate = CpuReferenceIntegrator(a.scene).bake(a.gbuffer, settings);
  for (size_t i = 0; i < a.gbuffer.texels.size(); ++i) {
    EXPECT_NEAR(estimate.mean_total(i).x, a.exact[i], 1e-5 * a.exact[i]) << "texel " << i;
    EXPECT_NEAR(estimate.mean_total(i).y, 2 * a.exact[i], 2e-5 * a.exact[i]) << "texel " << i;
  }
  expect_group_matches(estimate, all_texels(a.gbuffer), a.exact, a.colour, 1e-6, "point light");
}

TEST(AnalyticLighting, SpotLightConeEdges) {
  const AnalyticScene a = testing::spot_light_cone_edges();
  IntegratorSettings settings;
  settings.spp = 2;
  const LightmapEstimate estimate = CpuReferenceIntegrator(a.scene).bake(a.gbuffer, settings);
  for (size_t i = 0; i < a.gbuffer.texels.size(); ++i)
    EXPECT_NEAR(estimate.mean_total(i).x, a.exact[i], 1e-5 * a.exact[i] + 1e-9) << "texel " << i;
  EXPECT_EQ(estimate.mean_total(a.gbuffer.texels.size() - 1).x, 0.0f) << "outside the outer cone must be dark";
  EXPECT_EQ(estimate.mean_total(a.gbuffer.texels.size() - 2).x, 0.0f);
}

TEST(AnalyticLighting, DirectionalLightCosineLaw) {
  const AnalyticScene a = testing::directional_light_on_plane();
  IntegratorSettings settings;
  settings.spp = 4;
  const LightmapEstimate estimate = CpuReferenceIntegrator(a.scene).bake(a.gbuffer, settings);
  for (size_t i = 0; i < a.gbuffer.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double exact = a.colour[c] * a.exact[i];
      EXPECT_NEAR(estimate.mean_total(i)[c], exact, 1e-5 * exact);
    }
}

TEST(AnalyticLighting, FormFactorFormulasAgree) {
  // The point-to-rectangle formula averaged over the receiver equals the square-to-square value.
  const int n = 400;
  double sum = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double px = (i + 0.5) / n, pz = (j + 0.5) / n;
      sum += testing::point_to_rectangle_form_factor(-px, 1 - px, -pz, 1 - pz, 1.0);
    }
  EXPECT_NEAR(sum / (n * n), testing::unit_squares_form_factor(), 1e-5);
  EXPECT_NEAR(testing::unit_squares_form_factor(), 0.19982, 1e-5);
}

TEST(AnalyticLighting, TwoParallelUnitSquares) {
  const AnalyticScene a = testing::two_parallel_unit_squares();
  IntegratorSettings settings;
  settings.spp = 256;
  settings.seed = 11;
  const LightmapEstimate estimate = CpuReferenceIntegrator(a.scene).bake(a.gbuffer, settings);
  // Four quadrant groups (centre and corners differ by ~2x) and the whole receiver.
  for (int quadrant = 0; quadrant < 4; ++quadrant) {
    std::vector<size_t> group;
    std::vector<double> group_expected;
    for (size_t i = 0; i < a.gbuffer.texels.size(); ++i) {
      const Vec3 p = a.gbuffer.texels[i].position;
      if (int(p.x > 0.5f) + 2 * int(p.z > 0.5f) == quadrant) group.push_back(i), group_expected.push_back(a.exact[i]);
    }
    for (double& v : group_expected) v *= a.colour.x;
    const auto g = compare_group(estimate, group, group_expected, 0);
    EXPECT_LE(std::fabs(g.z()), kZLimit) << "quadrant " << quadrant;
    EXPECT_LE(g.standard_error, 0.01 * g.expected);
  }
  expect_group_matches(estimate, all_texels(a.gbuffer), a.exact, a.colour, 0.01, "parallel unit squares");
}

// With albedo 0 nothing bounces: indirect must be exactly zero and total equal direct.
TEST(AnalyticLighting, AlbedoZeroHasNoIndirectEnergy) {
  const AnalyticScene a = testing::albedo_zero_room();
  IntegratorSettings settings;
  settings.spp = 64;
  settings.recorded_bounces = 3;
  const LightmapEstimate estimate = CpuReferenceIntegrator(a.scene).bake(a.gbuffer, settings);
  for (size_t i = 0; i < a.gbuffer.texels.size(); ++i) {
    const Vec3 total = estimate.mean_total(i), direct = estimate.mean_direct(i);
    EXPECT_GT(total.x, 0.0f);
    EXPECT_FLOAT_EQ(total.x, direct.x);
    EXPECT_EQ(estimate.mean_bounce(1, i).x, 0.0f);
    EXPECT_EQ(estimate.mean_bounce(2, i).x, 0.0f);
  }
}

}  // namespace
}  // namespace exitance
