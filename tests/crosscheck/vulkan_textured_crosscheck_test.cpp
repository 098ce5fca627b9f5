// Per-point materials on the Vulkan backend (issue 13): textures (wrap modes, KHR_texture_transform,
// both UV sets), COLOR_0, emissive textures, alphaMode MASK and BLEND in traversal. Closed forms on
// the GPU alone: texels on y = 0 under a square at y = 0.5 (the analytic scenes of
// tests/analytic/alpha_coverage_test.cpp), E/pi from point-to-rectangle form factors, z-tests per
// channel and per side of the square (|z| < 4), each with a power check (the answer of a wrong
// implementation lies beyond 10 SE). Then the CPU reference against the GPU per region of texels on
// a scene with all of it. Validation layers on; without a Vulkan device, SKIP.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "support/analytic_scenes.h"
#include "support/lightmap_comparison.h"
#include "support/textured_scenes.h"
#include "support/validated_vulkan_backend.h"

namespace exitance {
namespace {

using testing::add_material;
using testing::add_quad;
using testing::compare_group;
using testing::grid_points;
using testing::point_to_rectangle_form_factor;
using testing::texel_at;

constexpr double kZLimit = 4.0;
constexpr float kHeight = 0.5f;  // the square [-0.5, 0.5]^2 at y = kHeight, facing down

std::vector<Vec3> floor_points() {
  std::vector<Vec3> points;
  for (Vec2 p : grid_points(4, 0.1f)) points.push_back({1.6f * p.x - 0.8f, 0.0f, 1.6f * p.y - 0.8f});
  return points;
}

// The square's form factor from p, restricted to x in [x0, x1] of the square.
double square_form_factor(Vec3 p, double x0 = -0.5, double x1 = 0.5) {
  return point_to_rectangle_form_factor(x0 - p.x, x1 - p.x, -0.5 - p.z, 0.5 - p.z, kHeight);
}

void add_square(Scene& scene, uint32_t material) {
  add_quad(scene, {-0.5f, kHeight, -0.5f}, {1, 0, 0}, {0, 0, 1}, material);  // u along +x
}

struct Outcome {
  double z_max = 0;
  double z_alternative = 1e9;
};

// GPU bake of the floor texels; z-test of the texels with x < 0 and those with x > 0 (per channel c)
// against expected(p, c), and the alternative's |z|.
template <typename Expected, typename Alternative>
void gpu_against_closed_form(const Scene& scene, const Expected& expected, const Alternative& alternative, const char* what,
                             Outcome& outcome) {
  TexelGBuffer gbuffer;
  for (Vec3 p : floor_points()) gbuffer.texels.push_back(texel_at(p, {0, 1, 0}));
  CREATE_VULKAN_OR_SKIP(vk, scene);
  IntegratorSettings settings;
  settings.spp = 2048;
  settings.seed = 13;
  const LightmapEstimate estimate = vk->bake(gbuffer, settings);
  EXPECT_EQ(estimate.nonfinite_samples, 0u);
  for (int side = 0; side < 2; ++side) {
    std::vector<size_t> texels;
    std::vector<double> e[3], a[3];
    for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
      const Vec3 p = gbuffer.texels[i].position;
      if ((p.x > 0) != (side == 1)) continue;
      texels.push_back(i);
      for (int c = 0; c < 3; ++c) e[c].push_back(expected(p, c)), a[c].push_back(alternative(p, c));
    }
    for (int c = 0; c < 3; ++c) {
      const auto g = compare_group(estimate, texels, e[c], c);
      const auto h = compare_group(estimate, texels, a[c], c);
      std::printf("[gpu textures] %-28s side %d ch%d exact %.6g estimate %.6g SE %.3g z %+.2f (alternative %.6g: z %+.1f)\n",
                  what, side, c, g.expected, g.estimate, g.standard_error, g.z(), h.expected, h.z());
      EXPECT_GT(g.standard_error, 0.0) << what;
      outcome.z_max = std::max(outcome.z_max, std::fabs(g.z()));
      outcome.z_alternative = std::min(outcome.z_alternative, std::fabs(h.z()));
    }
  }
}

// A 2 x 1 texture: alpha 0 on the left texel, 1 on the right; clamped, so coverage crosses 0.5 at u = 0.5.
Texture half_covered_texture() { return testing::two_halves_texture(2, {1, 1, 1}, 0.0f, {1, 1, 1}, 1.0f); }

TEST(VulkanTextures, EmissiveTextureLightsByItsHalves) {
  // 64 texels wide: left half a, right half b (bilinear blending within half a texel of u = 0.5
  // changes E/pi by ~1e-5 relative). E/pi = a F(left half) + b F(right half), per channel; the
  // alternative is the texture's mean over the whole square.
  const Vec3 a{2.0f, 0.5f, 1.0f}, b{0.25f, 3.0f, 0.2f};
  Scene scene;
  scene.textures.push_back(testing::two_halves_texture(64, a, 1.0f, b, 1.0f));
  scene.textures[0].alpha.clear();
  const uint32_t m = add_material(scene, {0, 0, 0}, {1, 1, 1});
  scene.materials[m].emissive_texture.texture = 0;
  add_square(scene, m);
  Outcome o;
  gpu_against_closed_form(
      scene, [&](Vec3 p, int c) { return a[c] * square_form_factor(p, -0.5, 0.0) + b[c] * square_form_factor(p, 0.0, 0.5); },
      [&](Vec3 p, int c) { return 0.5 * (a[c] + b[c]) * square_form_factor(p); }, "emissive halves", o);
  if (::testing::Test::IsSkipped()) return;
  EXPECT_LE(o.z_max, kZLimit);
  EXPECT_GT(o.z_alternative, 10.0) << "the test could not tell the textured emitter from its mean";
}

TEST(VulkanTextures, MaskTextureShadowsWhereCoverageReachesTheCutoff) {
  Scene scene;
  scene.sky.constant = {1.0f, 0.5f, 0.25f};
  scene.textures.push_back(half_covered_texture());
  const uint32_t m = add_material(scene, {0, 0, 0}, {0, 0, 0}, true);
  scene.materials[m].alpha_mode = Material::AlphaMode::Mask;
  scene.materials[m].base_color_texture.texture = 0;
  add_square(scene, m);
  Outcome o;
  gpu_against_closed_form(
      scene, [&](Vec3 p, int c) { return (1.0 - square_form_factor(p, 0.0, 0.5)) * scene.sky.constant[c]; },
      [&](Vec3 p, int c) { return (1.0 - square_form_factor(p)) * scene.sky.constant[c]; }, "MASK half", o);
  if (::testing::Test::IsSkipped()) return;
  EXPECT_LE(o.z_max, kZLimit);
  EXPECT_GT(o.z_alternative, 10.0) << "the test could not tell the masked square from the whole one";
}

TEST(VulkanTextures, MaskedEmitterLightsWithItsOpaquePartOnly) {
  const Vec3 le{2.0f, 1.0f, 4.0f};
  Scene scene;
  scene.textures.push_back(half_covered_texture());
  const uint32_t m = add_material(scene, {0, 0, 0}, le);
  scene.materials[m].alpha_mode = Material::AlphaMode::Mask;
  scene.materials[m].base_color_texture.texture = 0;
  add_square(scene, m);
  Outcome o;
  gpu_against_closed_form(
      scene, [&](Vec3 p, int c) { return square_form_factor(p, 0.0, 0.5) * le[c]; },
      [&](Vec3 p, int c) { return square_form_factor(p) * le[c]; }, "MASK emitter half", o);
  if (::testing::Test::IsSkipped()) return;
  EXPECT_LE(o.z_max, kZLimit);
  EXPECT_GT(o.z_alternative, 10.0) << "the test could not tell the masked emitter from the whole one";
}

TEST(VulkanTextures, BlendSquareShadowsInProportionToItsCoverage) {
  const float alpha = 0.3f;
  Scene scene;
  scene.sky.constant = {1.0f, 0.5f, 0.25f};
  const uint32_t m = add_material(scene, {0, 0, 0}, {0, 0, 0}, true);
  scene.materials[m].alpha_mode = Material::AlphaMode::Blend;
  scene.materials[m].base_alpha = alpha;
  add_square(scene, m);
  Outcome o;
  gpu_against_closed_form(
      scene, [&](Vec3 p, int c) { return (1.0 - alpha * square_form_factor(p)) * scene.sky.constant[c]; },
      [&](Vec3 p, int c) { return (1.0 - square_form_factor(p)) * scene.sky.constant[c]; }, "BLEND alpha 0.3", o);
  if (::testing::Test::IsSkipped()) return;
  EXPECT_LE(o.z_max, kZLimit);
  EXPECT_GT(o.z_alternative, 10.0) << "the test could not tell BLEND from OPAQUE";
}

// White textures (and white COLOR_0) multiply every factor by 1, so on each backend the textured
// path must give the untextured scene's lightmap up to float rounding: the same albedo, emission and
// random decisions at every vertex. The two paths round the albedo product differently (one ulp in
// 1 of 216 texel channels here), so the bound is 1e-5 relative; any changed decision (a Russian
// roulette or light choice) moves a texel by about one sample's share, 1/64 of its value, and a
// wrong fetch, a bilinear weight sum other than 1, or a lookup drawing a random number more.
// (bench/results/relight-gpu-assets.md measures the same on the building on the H200.)
TEST(VulkanTextures, WhiteTexturesChangeNoResultOnEitherBackend) {
  auto build = [](bool textured) {
    Scene s;
    s.sky.constant = {0.6f, 0.7f, 1.0f};
    const uint32_t floor = add_material(s, {0.8f, 0.6f, 0.4f});
    const uint32_t wall = add_material(s, {0.5f, 0.7f, 0.9f});
    const uint32_t panel = add_material(s, {0.5f, 0.5f, 0.5f}, {3.0f, 2.5f, 2.0f});
    if (textured) {
      s.textures.push_back(testing::checker_texture(8, {1, 1, 1}, {1, 1, 1}, Texture::Wrap::Repeat));
      s.textures.push_back(testing::checker_texture(4, {1, 1, 1}, {1, 1, 1}, Texture::Wrap::MirroredRepeat));
      s.materials[floor].base_color_texture.texture = 0;
      s.materials[floor].base_color_texture.transform.scale = {1.5f, 2.0f};
      s.materials[floor].base_color_texture.transform.rotation = 0.3f;
      s.materials[wall].base_color_texture.texture = 1;
      s.materials[wall].base_color_texture.transform.tex_coord = 1;
      s.materials[panel].emissive_texture.texture = 0;
    }
    add_quad(s, {-1, 0, 1}, {2, 0, 0}, {0, 0, -2}, floor);
    add_quad(s, {-1, 0, -1}, {2, 0, 0}, {0, 1.5f, 0}, wall);
    add_quad(s, {-0.3f, 1.2f, -0.3f}, {0.6f, 0, 0}, {0, 0, 0.6f}, panel);
    if (textured)
      for (size_t i = 0; i < s.positions.size(); ++i) s.vertex_color.push_back({1, 1, 1}), s.vertex_alpha.push_back(1.0f);
    return s;
  };
  const Scene plain = build(false), white = build(true);
  TexelGBuffer gbuffer;
  for (Vec2 p : grid_points(6, 0.1f)) {
    gbuffer.texels.push_back(texel_at({1.8f * p.x - 0.9f, 0, 1.8f * p.y - 0.9f}, {0, 1, 0}));
    gbuffer.texels.push_back(texel_at({1.8f * p.x - 0.9f, 0.05f + 1.4f * p.y, -1}, {0, 0, 1}));
  }
  IntegratorSettings settings;
  settings.spp = 64;
  settings.seed = 21;
  auto expect_same = [&](const LightmapEstimate& a, const LightmapEstimate& b, const char* backend) {
    ASSERT_EQ(a.texels.size(), b.texels.size());
    size_t lit = 0;
    for (size_t i = 0; i < a.texels.size(); ++i) {
      const Vec3 x = a.mean_total(i), y = b.mean_total(i);
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(x[c], y[c], 1e-5f * std::max(std::fabs(x[c]), 1e-4f)) << backend << " texel " << i << " channel " << c;
      lit += x[0] > 0 ? 1 : 0;
    }
    EXPECT_GT(lit, a.texels.size() / 2) << backend;
  };
  expect_same(CpuReferenceIntegrator(plain).bake(gbuffer, settings), CpuReferenceIntegrator(white).bake(gbuffer, settings), "cpu");
  CREATE_VULKAN_OR_SKIP(vk_plain, plain);
  CREATE_VULKAN_OR_SKIP(vk_white, white);
  expect_same(vk_plain->bake(gbuffer, settings), vk_white->bake(gbuffer, settings), "vulkan");
}

// Everything at once, CPU reference against the GPU: per region of 8 texels, z-tests with both
// estimators' variances (compare_estimates, |z| < 4), and relMSE of the converged results.
TEST(VulkanTextures, TexturedMaskedVertexColouredSceneMatchesTheReference) {
  const testing::TexturedScene t = testing::textured_masked_scene();
  TexelGBuffer gbuffer;
  gbuffer.texels = t.texels;
  CREATE_VULKAN_OR_SKIP(vk, t.scene);
  IntegratorSettings settings;
  settings.spp = 1024;
  settings.seed = 1001;
  const LightmapEstimate gpu = vk->bake(gbuffer, settings);
  settings.seed = 2002;
  const LightmapEstimate cpu = CpuReferenceIntegrator(t.scene).bake(gbuffer, settings);
  EXPECT_EQ(gpu.nonfinite_samples, 0u);
  const testing::Comparison c = testing::compare_estimates(gpu, cpu, 8, "textured scene");
  EXPECT_LT(c.rel_mse, 0.005);
  std::printf("[gpu textures] textured scene: %zu texels x %u spp, worst |z| %.2f, relMSE %.2e; seconds gpu %.2f cpu %.2f\n",
              gbuffer.texels.size(), settings.spp, c.worst_z, c.rel_mse, gpu.seconds, cpu.seconds);
}

}  // namespace
}  // namespace exitance
