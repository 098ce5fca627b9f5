// glTF alphaMode on the CPU backend (issue 13): a MASK surface stops rays only where its coverage
// reaches the cutoff, a BLEND surface stops a ray with probability equal to its coverage, and a
// masked emitter emits only where it is opaque. Each case is a closed form: texels under a constant
// sky (or an emitter) and a square at height 0.5, so E/pi = L (1 - coverage * F) with F the
// point-to-rectangle form factor. z-tests per channel within 4 standard errors, each with its own
// power check: the answer for an opaque (or fully transparent) square must lie beyond 10 standard
// errors, so a filter that does nothing fails.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "exitance/runtime/alpha_coverage.h"
#include "exitance/runtime/embree_scene.h"
#include "exitance/runtime/material_eval.h"
#include "support/analytic_scenes.h"

namespace exitance {
namespace {

using testing::add_material;
using testing::add_quad;
using testing::compare_group;
using testing::grid_points;
using testing::point_to_rectangle_form_factor;
using testing::texel_at;

constexpr double kZLimit = 4.0;
constexpr float kHeight = 0.5f;  // the square [-0.5, 0.5]^2 at y = kHeight

// Texels on y = 0 facing up, over [-0.8, 0.8]^2.
std::vector<Vec3> floor_points() {
  std::vector<Vec3> points;
  for (Vec2 p : grid_points(4, 0.1f)) points.push_back({1.6f * p.x - 0.8f, 0.0f, 1.6f * p.y - 0.8f});
  return points;
}

// The square's form factor from p, restricted to x in [x0, x1] of the square.
double square_form_factor(Vec3 p, double x0 = -0.5, double x1 = 0.5) {
  return point_to_rectangle_form_factor(x0 - p.x, x1 - p.x, -0.5 - p.z, 0.5 - p.z, kHeight);
}

// A 2 x 1 texture: alpha 0 on the left texel, 1 on the right; clamped, so bilinear coverage is 0
// for u < 0.25, 1 for u > 0.75, and crosses 0.5 exactly at u = 0.5.
Texture half_covered_texture() {
  Texture t;
  t.width = 2, t.height = 1;
  t.rgb = {1, 1, 1, 1, 1, 1};
  t.alpha = {0, 1};
  t.wrap_s = t.wrap_t = Texture::Wrap::ClampToEdge;
  return t;
}

// Adds the square, facing down (cross(u, v) = -y), with the given material.
void add_square(Scene& scene, uint32_t material) {
  add_quad(scene, {-0.5f, kHeight, -0.5f}, {1, 0, 0}, {0, 0, 1}, material);
}

struct Outcome {
  double z_max = 0;            // largest |z| over channels against the expected values
  double z_alternative = 1e9;  // smallest |z| against the alternative (power)
};

Outcome bake_and_compare(const Scene& scene, const std::vector<double>& expected,
                         const std::vector<double>& alternative, Vec3 colour, const char* what) {
  TexelGBuffer gbuffer;
  for (Vec3 p : floor_points()) gbuffer.texels.push_back(texel_at(p, {0, 1, 0}));
  IntegratorSettings settings;
  settings.spp = 2048;
  settings.seed = 11;
  const LightmapEstimate estimate = CpuReferenceIntegrator(scene).bake(gbuffer, settings);
  EXPECT_EQ(estimate.nonfinite_samples, 0u);
  std::vector<size_t> texels(gbuffer.texels.size());
  for (size_t i = 0; i < texels.size(); ++i) texels[i] = i;
  Outcome outcome;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> e(expected), a(alternative);
    for (double& v : e) v *= colour[c];
    for (double& v : a) v *= colour[c];
    const auto g = compare_group(estimate, texels, e, c);
    const auto h = compare_group(estimate, texels, a, c);
    std::printf("[alpha] %-32s ch%d exact %.6g estimate %.6g SE %.3g z %+.2f (alternative %.6g: z %+.1f)\n", what, c,
                g.expected, g.estimate, g.standard_error, g.z(), h.expected, h.z());
    EXPECT_GT(g.standard_error, 0.0) << what;
    outcome.z_max = std::max(outcome.z_max, std::fabs(g.z()));
    outcome.z_alternative = std::min(outcome.z_alternative, std::fabs(h.z()));
  }
  return outcome;
}

TEST(AlphaCoverage, BlendSquareShadowsInProportionToItsCoverage) {
  const float alpha = 0.3f;
  Scene scene;
  scene.sky.constant = {1.0f, 0.5f, 0.25f};
  const uint32_t m = add_material(scene, {0, 0, 0}, {0, 0, 0}, true);
  scene.materials[m].alpha_mode = Material::AlphaMode::Blend;
  scene.materials[m].base_alpha = alpha;
  add_square(scene, m);
  std::vector<double> expected, opaque;
  for (Vec3 p : floor_points()) {
    expected.push_back(1.0 - alpha * square_form_factor(p));
    opaque.push_back(1.0 - square_form_factor(p));
  }
  const Outcome o = bake_and_compare(scene, expected, opaque, scene.sky.constant, "BLEND alpha 0.3");
  EXPECT_LE(o.z_max, kZLimit);
  EXPECT_GT(o.z_alternative, 10.0) << "the test could not tell BLEND from OPAQUE";
}

TEST(AlphaCoverage, MaskTextureShadowsWhereCoverageReachesTheCutoff) {
  Scene scene;
  scene.sky.constant = {1.0f, 0.5f, 0.25f};
  scene.textures.push_back(half_covered_texture());
  const uint32_t m = add_material(scene, {0, 0, 0}, {0, 0, 0}, true);
  scene.materials[m].alpha_mode = Material::AlphaMode::Mask;
  scene.materials[m].alpha_cutoff = 0.5f;
  scene.materials[m].base_color_texture.texture = 0;
  add_square(scene, m);
  // add_quad maps u along +x: the opaque half is x in [0, 0.5].
  std::vector<double> expected, whole;
  for (Vec3 p : floor_points()) {
    expected.push_back(1.0 - square_form_factor(p, 0.0, 0.5));
    whole.push_back(1.0 - square_form_factor(p));
  }
  const Outcome o = bake_and_compare(scene, expected, whole, scene.sky.constant, "MASK half");
  EXPECT_LE(o.z_max, kZLimit);
  EXPECT_GT(o.z_alternative, 10.0) << "the test could not tell the masked square from the whole one";
}

TEST(AlphaCoverage, MaskedEmitterLightsWithItsOpaquePartOnly) {
  // The square emits downwards; light sampling picks points on its whole area, paths hit only its
  // opaque half: both must agree on Le * F(opaque half).
  const Vec3 le{2.0f, 1.0f, 4.0f};
  Scene scene;
  scene.textures.push_back(half_covered_texture());
  const uint32_t m = add_material(scene, {0, 0, 0}, le);
  scene.materials[m].alpha_mode = Material::AlphaMode::Mask;
  scene.materials[m].base_color_texture.texture = 0;
  add_square(scene, m);
  std::vector<double> expected, whole;
  for (Vec3 p : floor_points()) {
    expected.push_back(square_form_factor(p, 0.0, 0.5));
    whole.push_back(square_form_factor(p));
  }
  const Outcome o = bake_and_compare(scene, expected, whole, le, "MASK emitter half");
  EXPECT_LE(o.z_max, kZLimit);
  EXPECT_GT(o.z_alternative, 10.0) << "the test could not tell the masked emitter from the whole one";
}

TEST(AlphaCoverage, RaysPassOnlyWhereTransparent) {
  Scene scene;
  scene.textures.push_back(half_covered_texture());
  const uint32_t m = add_material(scene, {0.5f, 0.5f, 0.5f}, {0, 0, 0}, true);
  scene.materials[m].alpha_mode = Material::AlphaMode::Mask;
  scene.materials[m].base_color_texture.texture = 0;
  add_square(scene, m);
  const EmbreeScene embree(scene);
  for (float x : {-0.45f, -0.3f, -0.05f, 0.05f, 0.3f, 0.45f}) {
    const bool opaque = x > 0;
    EXPECT_EQ(embree.intersect({x, 0, 0.1f}, {0, 1, 0}, 10).found, opaque) << "x " << x;
    EXPECT_EQ(embree.occluded({x, 0, 0.1f}, {0, 1, 0}, 10), opaque) << "x " << x;
  }
  scene.materials[m].base_alpha = 0.49f;  // below the cutoff everywhere
  const EmbreeScene faded(scene);
  EXPECT_FALSE(faded.occluded({0.3f, 0, 0.1f}, {0, 1, 0}, 10));
}

TEST(AlphaCoverage, BlendDecisionNumbersAreUniformAndRepeatable) {
  double sum = 0, sum_squared = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const Vec3 origin{0.001f * float(i % 997), 0.37f, -0.002f * float(i / 997)};
    const float u = blend_decision_number(origin, {0, 1, 0}, uint32_t(i % 7));
    ASSERT_GE(u, 0.0f);
    ASSERT_LT(u, 1.0f);
    EXPECT_EQ(u, blend_decision_number(origin, {0, 1, 0}, uint32_t(i % 7)));
    sum += u, sum_squared += double(u) * u;
  }
  // Uniform: mean 1/2 (SE sqrt(1/12/n)) and second moment 1/3 (SE sqrt(4/45/n)).
  EXPECT_LE(std::fabs(sum / n - 0.5), kZLimit * std::sqrt(1.0 / 12 / n));
  EXPECT_LE(std::fabs(sum_squared / n - 1.0 / 3), kZLimit * std::sqrt(4.0 / 45 / n));
}

}  // namespace
}  // namespace exitance
