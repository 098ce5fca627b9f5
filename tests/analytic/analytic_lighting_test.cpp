// Closed-form checks of the CPU reference integrator (DESIGN §6.1). Every comparison is a
// z-test of a texel group against the exact value within 4 standard errors estimated from the
// samples themselves, plus a bound on the standard error so a noisy estimator cannot pass by
// being vague. Deterministic cases (zero variance) must match to float rounding.
#include <gtest/gtest.h>

#include <cmath>

#include "exitance/runtime/sampling.h"
#include "support/test_scenes.h"

namespace exitance {
namespace {

using testing::add_inward_box;
using testing::add_material;
using testing::add_quad;
using testing::compare_group;
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

// The points of a 8x8 grid on the unit square [0,1]^2 in the (a, b) plane coordinates.
std::vector<Vec2> grid_points(int n, float margin) {
  std::vector<Vec2> points;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      points.push_back({margin + (1 - 2 * margin) * (float(i) + 0.5f) / float(n),
                        margin + (1 - 2 * margin) * (float(j) + 0.5f) / float(n)});
  return points;
}

void run_furnace(float albedo, uint32_t spp, double max_relative_se) {
  Scene scene;
  const Vec3 le{1.0f, 0.5f, 0.25f};
  add_inward_box(scene, {0, 0, 0}, {1, 1, 1}, add_material(scene, {albedo, albedo, albedo}, le));
  TexelGBuffer gbuffer;
  for (Vec2 p : grid_points(4, 0.1f)) {
    gbuffer.texels.push_back(texel_at({p.x, 0.0f, p.y}, {0, 1, 0}));   // floor
    gbuffer.texels.push_back(texel_at({p.x, p.y, 0.0f}, {0, 0, 1}));   // back wall
    gbuffer.texels.push_back(texel_at({1.0f, p.x, p.y}, {-1, 0, 0}));  // right wall
    gbuffer.texels.push_back(texel_at({p.x, 1.0f, p.y}, {0, -1, 0}));  // ceiling
  }
  IntegratorSettings settings;
  settings.spp = spp;
  settings.seed = 7;
  const LightmapEstimate estimate = CpuReferenceIntegrator(scene).bake(gbuffer, settings);
  const std::vector<size_t> texels = all_texels(gbuffer);
  for (int c = 0; c < 3; ++c) {
    std::vector<double> expected(texels.size(), le[c] / (1.0 - albedo));
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

TEST(AnalyticLighting, PlaneUnderConstantSky) {
  Scene scene;
  add_quad(scene, {-1, 0, 1}, {2, 0, 0}, {0, 0, -2}, add_material(scene, {0.8f, 0.8f, 0.8f}));
  scene.sky.constant = {0.5f, 1.0f, 2.0f};
  TexelGBuffer gbuffer;
  for (Vec2 p : grid_points(8, 0.0f)) gbuffer.texels.push_back(texel_at({2 * p.x - 1, 0, 2 * p.y - 1}, {0, 1, 0}));
  IntegratorSettings settings;
  settings.spp = 16;
  const LightmapEstimate estimate = CpuReferenceIntegrator(scene).bake(gbuffer, settings);
  for (size_t i = 0; i < gbuffer.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(estimate.mean_total(i)[c], scene.sky.constant[c], 1e-5 * scene.sky.constant[c]);
  expect_group_matches(estimate, all_texels(gbuffer), std::vector<double>(gbuffer.texels.size(), 1.0), scene.sky.constant, 1e-6,
                       "plane under constant sky");
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
  Scene scene;
  add_quad(scene, {-4, 0, 4}, {8, 0, 0}, {0, 0, -8}, add_material(scene, {0.7f, 0.7f, 0.7f}));
  PunctualLight light;
  light.type = PunctualLight::Type::Point;
  light.position = {0.3f, 2.0f, -0.2f};
  light.intensity = {10.0f, 20.0f, 5.0f};
  scene.lights.push_back(light);
  TexelGBuffer gbuffer;
  std::vector<double> expected_red;
  for (Vec2 p : grid_points(6, 0.0f)) {
    const Vec3 x{6 * p.x - 3, 0, 6 * p.y - 3};
    gbuffer.texels.push_back(texel_at(x, {0, 1, 0}));
    const Vec3 d = light.position - x;
    const double dist2 = dot(d, d), cos_theta = d.y / std::sqrt(dist2);
    expected_red.push_back(10.0 * cos_theta / (kPi * dist2));
  }
  IntegratorSettings settings;
  settings.spp = 4;
  const LightmapEstimate estimate = CpuReferenceIntegrator(scene).bake(gbuffer, settings);
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    EXPECT_NEAR(estimate.mean_total(i).x, expected_red[i], 1e-5 * expected_red[i]) << "texel " << i;
    EXPECT_NEAR(estimate.mean_total(i).y, 2 * expected_red[i], 2e-5 * expected_red[i]) << "texel " << i;
  }
  expect_group_matches(estimate, all_texels(gbuffer), expected_red, {1.0f, 2.0f, 0.5f}, 1e-6, "point light");
}

TEST(AnalyticLighting, SpotLightConeEdges) {
  Scene scene;
  add_quad(scene, {-4, 0, 4}, {8, 0, 0}, {0, 0, -8}, add_material(scene, {0.0f, 0.0f, 0.0f}));
  PunctualLight spot;
  spot.type = PunctualLight::Type::Spot;
  spot.position = {0, 2, 0};
  spot.direction = {0, -1, 0};
  spot.intensity = {50, 50, 50};
  const double inner = 20.0 * kPi / 180.0, outer = 30.0 * kPi / 180.0;
  spot.cos_inner = float(std::cos(inner));
  spot.cos_outer = float(std::cos(outer));
  scene.lights.push_back(spot);
  TexelGBuffer gbuffer;
  std::vector<double> expected;
  for (double degrees : {0.0, 10.0, 19.5, 21.0, 25.0, 29.0, 30.5, 40.0}) {
    const double angle = degrees * kPi / 180.0;
    const double r = 2.0 * std::tan(angle);
    gbuffer.texels.push_back(texel_at({float(r), 0, 0}, {0, 1, 0}));
    const double cd = std::cos(angle);
    const double t = std::clamp((cd - std::cos(outer)) / (std::cos(inner) - std::cos(outer)), 0.0, 1.0);
    const double dist2 = 4.0 + r * r;
    expected.push_back(50.0 * t * t * cd / (kPi * dist2));
  }
  IntegratorSettings settings;
  settings.spp = 2;
  const LightmapEstimate estimate = CpuReferenceIntegrator(scene).bake(gbuffer, settings);
  for (size_t i = 0; i < gbuffer.texels.size(); ++i)
    EXPECT_NEAR(estimate.mean_total(i).x, expected[i], 1e-5 * expected[i] + 1e-9) << "texel " << i;
  EXPECT_EQ(estimate.mean_total(gbuffer.texels.size() - 1).x, 0.0f) << "outside the outer cone must be dark";
  EXPECT_EQ(estimate.mean_total(gbuffer.texels.size() - 2).x, 0.0f);
}

TEST(AnalyticLighting, DirectionalLightCosineLaw) {
  Scene scene;
  add_quad(scene, {-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, add_material(scene, {0.5f, 0.5f, 0.5f}));
  PunctualLight sun;
  sun.type = PunctualLight::Type::Directional;
  sun.direction = normalize(Vec3{0.3f, -0.8f, 0.52f});
  sun.intensity = {3.0f, 2.0f, 1.0f};
  scene.lights.push_back(sun);
  TexelGBuffer gbuffer;
  for (Vec2 p : grid_points(4, 0.1f)) gbuffer.texels.push_back(texel_at({4 * p.x - 2, 0, 4 * p.y - 2}, {0, 1, 0}));
  IntegratorSettings settings;
  settings.spp = 4;
  const LightmapEstimate estimate = CpuReferenceIntegrator(scene).bake(gbuffer, settings);
  const double cos_theta = -sun.direction.y;
  for (size_t i = 0; i < gbuffer.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double exact = sun.intensity[c] * cos_theta / kPi;
      EXPECT_NEAR(estimate.mean_total(i)[c], exact, 1e-5 * exact);
    }
}

// Form factor from a differential area to a parallel rectangle with one corner above it
// (sides a, b at distance d): the classic closed form.
double corner_form_factor(double a, double b, double d) {
  const double x = a / d, y = b / d;
  const double sx = std::sqrt(1 + x * x), sy = std::sqrt(1 + y * y);
  return (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy)) / (2 * kPi);
}

// Superposition of four corner rectangles for a rectangle [x0,x1] x [z0,z1] seen from the origin.
double point_to_rectangle_form_factor(double x0, double x1, double z0, double z1, double d) {
  auto f = [&](double x, double z) {
    const double s = (x < 0 ? -1.0 : 1.0) * (z < 0 ? -1.0 : 1.0);
    return s * corner_form_factor(std::fabs(x), std::fabs(z), d);
  };
  return f(x1, z1) - f(x0, z1) - f(x1, z0) + f(x0, z0);
}

// Closed-form form factor between two coaxial parallel unit squares one unit apart.
double unit_squares_form_factor() {
  const double x = 1.0, y = 1.0;  // sides over distance
  const double a = std::sqrt((1 + x * x) * (1 + y * y) / (1 + x * x + y * y));
  return 2.0 / (kPi * x * y) *
         (std::log(a) + x * std::sqrt(1 + y * y) * std::atan(x / std::sqrt(1 + y * y)) +
          y * std::sqrt(1 + x * x) * std::atan(y / std::sqrt(1 + x * x)) - x * std::atan(x) - y * std::atan(y));
}

TEST(AnalyticLighting, FormFactorFormulasAgree) {
  // The point-to-rectangle formula averaged over the receiver equals the square-to-square value.
  const int n = 400;
  double sum = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double px = (i + 0.5) / n, pz = (j + 0.5) / n;
      sum += point_to_rectangle_form_factor(-px, 1 - px, -pz, 1 - pz, 1.0);
    }
  EXPECT_NEAR(sum / (n * n), unit_squares_form_factor(), 1e-5);
  EXPECT_NEAR(unit_squares_form_factor(), 0.19982, 1e-5);
}

TEST(AnalyticLighting, TwoParallelUnitSquares) {
  Scene scene;
  const Vec3 le{2.0f, 1.0f, 0.5f};
  // Receiver at y=0 facing up (black, so no interreflection); emitter at y=1 facing down.
  add_quad(scene, {0, 0, 1}, {1, 0, 0}, {0, 0, -1}, add_material(scene, {0, 0, 0}));
  add_quad(scene, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}, add_material(scene, {0, 0, 0}, le));
  TexelGBuffer gbuffer;
  std::vector<double> expected;
  const std::vector<Vec2> points = grid_points(8, 0.0f);
  for (Vec2 p : points) {
    gbuffer.texels.push_back(texel_at({p.x, 0, p.y}, {0, 1, 0}));
    expected.push_back(point_to_rectangle_form_factor(-p.x, 1 - p.x, -p.y, 1 - p.y, 1.0));
  }
  IntegratorSettings settings;
  settings.spp = 256;
  settings.seed = 11;
  const LightmapEstimate estimate = CpuReferenceIntegrator(scene).bake(gbuffer, settings);
  // Four quadrant groups (centre and corners differ by ~2x) and the whole receiver.
  for (int quadrant = 0; quadrant < 4; ++quadrant) {
    std::vector<size_t> group;
    std::vector<double> group_expected;
    for (size_t i = 0; i < points.size(); ++i)
      if (int(points[i].x > 0.5f) + 2 * int(points[i].y > 0.5f) == quadrant)
        group.push_back(i), group_expected.push_back(expected[i]);
    for (double& v : group_expected) v *= le.x;
    const auto g = compare_group(estimate, group, group_expected, 0);
    EXPECT_LE(std::fabs(g.z()), kZLimit) << "quadrant " << quadrant;
    EXPECT_LE(g.standard_error, 0.01 * g.expected);
  }
  expect_group_matches(estimate, all_texels(gbuffer), expected, le, 0.01, "parallel unit squares");
}

// With albedo 0 nothing bounces: indirect must be exactly zero and total equal direct.
TEST(AnalyticLighting, AlbedoZeroHasNoIndirectEnergy) {
  Scene scene;
  const uint32_t black = add_material(scene, {0, 0, 0});
  add_quad(scene, {0, 0, 1}, {1, 0, 0}, {0, 0, -1}, black);                               // floor
  add_quad(scene, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}, add_material(scene, {0, 0, 0}, {1, 1, 1}));  // emissive ceiling
  add_quad(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, black);                                // back wall
  add_quad(scene, {0, 0, 0}, {0, 1, 0}, {0, 0, 1}, black);                                // left wall
  TexelGBuffer gbuffer;
  for (Vec2 p : grid_points(4, 0.1f)) {
    gbuffer.texels.push_back(texel_at({p.x, 0, p.y}, {0, 1, 0}));
    gbuffer.texels.push_back(texel_at({p.x, p.y, 0}, {0, 0, 1}));
  }
  IntegratorSettings settings;
  settings.spp = 64;
  settings.recorded_bounces = 3;
  const LightmapEstimate estimate = CpuReferenceIntegrator(scene).bake(gbuffer, settings);
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    const Vec3 total = estimate.mean_total(i), direct = estimate.mean_direct(i);
    EXPECT_GT(total.x, 0.0f);
    EXPECT_FLOAT_EQ(total.x, direct.x);
    EXPECT_EQ(estimate.mean_bounce(1, i).x, 0.0f);
    EXPECT_EQ(estimate.mean_bounce(2, i).x, 0.0f);
  }
}

}  // namespace
}  // namespace exitance
