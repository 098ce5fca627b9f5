// Numerical stress tests of the CPU reference (issue: run time against error / stress suite):
// extreme scales and offsets, albedo 0.99, a tiny very bright emitter, degenerate geometry,
// lights inside closed geometry and thin walls. Each reports its figures on stdout.
#include <gtest/gtest.h>

#include <cmath>

#include "exitance/bake/voxelize/svo_build.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "support/test_scenes.h"

namespace exitance {
namespace {

using testing::add_inward_box;
using testing::add_material;
using testing::add_quad;
using testing::texel_at;

// A Cornell-style room [0,4]^3 scaled by `scale` and moved by `offset`: inward walls, one
// emissive 1x1 panel facing down just under the ceiling, a box on the floor.
struct Room {
  Scene scene;
  TexelGBuffer texels;
};

Room make_room(float scale, Vec3 offset) {
  Room room;
  Scene& s = room.scene;
  auto P = [&](Vec3 p) { return p * scale + offset; };
  auto V = [&](Vec3 v) { return v * scale; };
  const uint32_t white = add_material(s, {0.7f, 0.7f, 0.7f});
  const uint32_t red = add_material(s, {0.6f, 0.1f, 0.1f});
  const uint32_t light = add_material(s, {0, 0, 0}, {10, 9, 8});
  add_quad(s, P({0, 0, 4}), V({4, 0, 0}), V({0, 0, -4}), white);  // floor (+y)
  add_quad(s, P({0, 4, 0}), V({4, 0, 0}), V({0, 0, 4}), white);   // ceiling (-y)
  add_quad(s, P({0, 0, 0}), V({4, 0, 0}), V({0, 4, 0}), white);   // back (+z)
  add_quad(s, P({0, 0, 4}), V({0, 4, 0}), V({4, 0, 0}), white);   // front (-z)
  add_quad(s, P({0, 0, 0}), V({0, 4, 0}), V({0, 0, 4}), red);     // left (+x)
  add_quad(s, P({4, 0, 0}), V({0, 0, 4}), V({0, 4, 0}), white);   // right (-x)
  add_quad(s, P({1.5f, 3.9f, 1.5f}), V({1, 0, 0}), V({0, 0, 1}), light);  // panel 10 cm under the ceiling
  // A 1x1x1 box standing on the floor (outward faces; bottom omitted).
  add_quad(s, P({1, 1, 2}), V({1, 0, 0}), V({0, 0, -1}), white);  // top (+y)
  add_quad(s, P({1, 0, 1}), V({0, 1, 0}), V({1, 0, 0}), white);   // -z side
  add_quad(s, P({1, 0, 2}), V({1, 0, 0}), V({0, 1, 0}), white);   // +z side
  add_quad(s, P({1, 0, 1}), V({0, 0, 1}), V({0, 1, 0}), white);   // -x side
  add_quad(s, P({2, 0, 1}), V({0, 1, 0}), V({0, 0, 1}), white);   // +x side
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const float a = 0.5f + float(i), b = 0.5f + float(j);
      room.texels.texels.push_back(texel_at(P({a, 0, b}), {0, 1, 0}));     // floor
      room.texels.texels.push_back(texel_at(P({a, b, 0}), {0, 0, 1}));     // back wall
      room.texels.texels.push_back(texel_at(P({0, a, b}), {1, 0, 0}));     // red wall
      room.texels.texels.push_back(texel_at(P({a, 4, b}), {0, -1, 0}));    // ceiling
    }
  return room;
}

// Every stress test runs on each backend: the CPU reference, the CPU reference with grid or SVO
// guiding forced on, and the Vulkan compute backend (lavapipe in CI, validation layers on; any validation
// message fails the test), unguided and with grid or SVO guiding forced on.
class Stress : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    if (GetParam().rfind("vulkan", 0) != 0) return;
    bool usable = false;
    for (const VulkanDeviceInfo& d : enumerate_vulkan_devices()) usable = usable || d.usable;
    if (!usable) GTEST_SKIP() << "no usable Vulkan device";
  }

  LightmapEstimate bake_scene(const Scene& scene, const TexelGBuffer& texels, const IntegratorSettings& settings) {
    if (GetParam() == "cpu") return CpuReferenceIntegrator(scene).bake(texels, settings);
    if (GetParam() == "cpu_guided") {  // grid guiding forced on (issue 11): same checks, same tolerances
      IntegratorSettings guided = settings;
      guided.guiding = GuidingMode::Grid;
      return CpuReferenceIntegrator(scene).bake(texels, guided);
    }
    // SVO guiding forced on, over a 64^3 octree of the scene (the octree outlives the bake below).
    formats::SparseVoxelOctree octree;
    if (GetParam() == "cpu_svo_guided" || GetParam() == "vulkan_svo_guided") {
      SvoBuildSettings build;
      build.depth = 6;
      octree = build_sparse_voxel_octree(scene, build);
    }
    if (GetParam() == "cpu_svo_guided") {
      IntegratorSettings guided = settings;
      guided.guiding = GuidingMode::Svo;
      guided.guiding_octree = &octree;
      return CpuReferenceIntegrator(scene).bake(texels, guided);
    }
    IntegratorSettings vulkan_settings = settings;
    if (GetParam() == "vulkan_guided") vulkan_settings.guiding = GuidingMode::Grid;  // same checks, same tolerances
    if (GetParam() == "vulkan_svo_guided") vulkan_settings.guiding = GuidingMode::Svo, vulkan_settings.guiding_octree = &octree;
    std::vector<std::string> messages;
    VulkanDeviceOptions options;
    options.validation = true;
    options.on_validation_message = [&messages](const std::string& m) { messages.push_back(m); };
    LightmapEstimate estimate;
    {
      const auto integrator = VulkanIntegrator::create(make_lighting_scene(scene), options);
      estimate = integrator->bake(texels, vulkan_settings);
    }
    EXPECT_TRUE(messages.empty()) << messages.size() << " validation messages, first: " << messages.front();
    return estimate;
  }

  LightmapEstimate bake(const Room& room, uint32_t spp, uint64_t seed) {
    IntegratorSettings settings;
    settings.spp = spp;
    settings.seed = seed;
    return bake_scene(room.scene, room.texels, settings);
  }
};

// Largest |z| over texels of the difference between two independent estimates.
double max_abs_z(const LightmapEstimate& a, const LightmapEstimate& b, size_t& compared) {
  double worst = 0;
  compared = 0;
  for (size_t i = 0; i < a.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double se = std::sqrt(double(a.variance_of_mean(i)[c]) + double(b.variance_of_mean(i)[c]));
      if (se <= 0) continue;
      worst = std::max(worst, std::fabs(double(a.mean_total(i)[c]) - double(b.mean_total(i)[c])) / se);
      ++compared;
    }
  return worst;
}

void expect_finite(const LightmapEstimate& e) {
  EXPECT_EQ(e.nonfinite_samples, 0u);
  for (size_t i = 0; i < e.texels.size(); ++i) ASSERT_TRUE(is_finite(e.mean_total(i))) << "texel " << i;
}

TEST_P(Stress, ScaleInvariance) {
  const LightmapEstimate base = bake(make_room(1.0f, {}), 256, 1);
  for (float scale : {1e-3f, 1e4f}) {
    const LightmapEstimate scaled = bake(make_room(scale, {}), 256, 2);
    expect_finite(scaled);
    size_t compared = 0;
    const double z = max_abs_z(base, scaled, compared);
    // 192 texel-channels: the largest of that many |z| exceeds 4.5 with probability < 0.2 %.
    EXPECT_LT(z, 4.5) << "scale " << scale;
    std::printf("[stress %s] scale %-6g max |z| over %zu texel-channels = %.2f\n", GetParam().c_str(), scale, compared, z);
  }
}

TEST_P(Stress, FarFromOriginNoSelfIntersection) {
  const LightmapEstimate base = bake(make_room(1.0f, {}), 1024, 3);
  const LightmapEstimate moved = bake(make_room(1.0f, {1e5f, 1e5f, -1e5f}), 1024, 4);
  expect_finite(moved);
  double rel_mse = 0, noise = 0;
  size_t n = 0;
  for (size_t i = 0; i < base.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double r = base.mean_total(i)[c], x = moved.mean_total(i)[c];
      if (r <= 0) continue;
      rel_mse += (x - r) * (x - r) / (r * r);
      noise += (double(base.variance_of_mean(i)[c]) + double(moved.variance_of_mean(i)[c])) / (r * r);
      ++n;
    }
  rel_mse /= double(n);
  noise /= double(n);
  std::printf("[stress %s] offset 1e5: relMSE vs unmoved %.3g (expected from noise alone %.3g)\n", GetParam().c_str(), rel_mse, noise);
  EXPECT_LT(rel_mse, 0.01);
  // Systematic self-intersection shows up as error well beyond the noise of the two estimates.
  EXPECT_LT(rel_mse, 2.0 * noise + 1e-4);
}

TEST_P(Stress, FurnaceAlbedo099IsUnbiased) {
  Scene scene;
  add_inward_box(scene, {0, 0, 0}, {1, 1, 1}, add_material(scene, {0.99f, 0.99f, 0.99f}, {1, 1, 1}));
  TexelGBuffer gbuffer;
  for (int i = 0; i < 64; ++i) gbuffer.texels.push_back(texel_at({0.1f + 0.0125f * float(i), 0, 0.5f}, {0, 1, 0}));
  IntegratorSettings settings;
  settings.spp = 256;
  settings.seed = 5;
  const LightmapEstimate e = bake_scene(scene, gbuffer, settings);
  double mean = 0, variance = 0;
  for (size_t i = 0; i < e.texels.size(); ++i) mean += e.mean_total(i).x, variance += e.variance_of_mean(i).x;
  mean /= double(e.texels.size());
  const double se = std::sqrt(variance) / double(e.texels.size());
  std::printf("[stress %s] furnace rho=0.99: exact 100 estimate %.4g SE %.3g z %+.2f (rays %llu; bounce cap %d)\n", GetParam().c_str(), mean,
              se, (mean - 100.0) / se, static_cast<unsigned long long>(e.rays), settings.safety_bounce_cap);
  EXPECT_LT(std::fabs(mean - 100.0), 4.0 * se);
  EXPECT_LT(se, 1.0);
}

TEST_P(Stress, TinyVeryBrightEmitter) {
  Room room = make_room(1.0f, {});
  // Area 1e-4 (1 cm x 1 cm), radiance 1e8, facing down from 3.5 m.
  const uint32_t hot = add_material(room.scene, {0, 0, 0}, {1e8f, 1e8f, 1e8f});
  add_quad(room.scene, {2.5f, 3.5f, 2.5f}, {0.01f, 0, 0}, {0, 0, 0.01f}, hot);
  const LightmapEstimate e = bake(room, 256, 6);
  expect_finite(e);
  // Outliers: samples of a texel beyond 10x its mean show up as a large standard error relative to
  // the mean; count texels whose relative SE exceeds 0.25 and report them (not clamped).
  size_t noisy = 0;
  double worst = 0;
  for (size_t i = 0; i < e.texels.size(); ++i) {
    const double m = luminance(e.mean_total(i)), se = std::sqrt(luminance(e.variance_of_mean(i)));
    ASSERT_TRUE(std::isfinite(se));
    if (m > 0) worst = std::max(worst, se / m), noisy += se / m > 0.25 ? 1 : 0;
  }
  std::printf("[stress %s] tiny bright emitter: %zu of %zu texels with relative SE > 0.25, worst %.3f\n", GetParam().c_str(), noisy,
              e.texels.size(), worst);
  // The emitter is sampled by next-event estimation; MIS keeps its contribution finite-variance.
  EXPECT_LT(worst, 0.5);
}

TEST_P(Stress, DegenerateGeometryAndHiddenLights) {
  Room room = make_room(1.0f, {});
  Scene& s = room.scene;
  const uint32_t white = add_material(s, {0.7f, 0.7f, 0.7f});
  const uint32_t glow = add_material(s, {0, 0, 0}, {5, 5, 5});
  // Zero-area emitter (collapsed quad), a sliver triangle pair, and a coplanar duplicate of the floor.
  add_quad(s, {2, 2, 2}, {0, 0, 0}, {0, 0, 1}, glow);
  add_quad(s, {0.2f, 1.0f, 3.0f}, {3.0f, 0, 0}, {0, 1e-7f, 0}, white);
  add_quad(s, {0, 0, 4}, {4, 0, 0}, {0, 0, -4}, white);
  // A point light inside the closed box: it must light nothing outside.
  PunctualLight hidden;
  hidden.position = {1.5f, 0.5f, 1.5f};
  hidden.intensity = {100, 100, 100};
  s.lights.push_back(hidden);
  // A back-facing texel: its normal points into the wall.
  room.texels.texels.push_back(texel_at({2, 2, 0}, {0, 0, -1}));
  const LightmapEstimate e = bake(room, 64, 7);
  expect_finite(e);
  EXPECT_EQ(e.mean_total(room.texels.texels.size() - 1).x, 0.0f) << "a texel facing out of the room sees nothing";
  // The hidden light contributes nothing: compare with the same room without it.
  Room plain = make_room(1.0f, {});
  const LightmapEstimate reference = bake(plain, 64, 7);
  double z_sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < plain.texels.texels.size(); ++i) {
    const double d = double(e.mean_total(i).x) - double(reference.mean_total(i).x);
    const double se = std::sqrt(double(e.variance_of_mean(i).x) + double(reference.variance_of_mean(i).x));
    if (se > 0) z_sum += d / se, ++n;
  }
  const double mean_z = z_sum / std::sqrt(double(n));  // sum of n unit normals / sqrt(n) is a unit normal
  std::printf("[stress %s] degenerate geometry + hidden light: combined z vs plain room %+.2f over %zu texels\n", GetParam().c_str(), mean_z, n);
  EXPECT_LT(std::fabs(mean_z), 4.0);
}

TEST_P(Stress, ThinWallDoesNotLeak) {
  // Two rooms side by side sharing a wall 1/10 of a 5 cm texel thick; only the left room is lit.
  Scene scene;
  const uint32_t white = add_material(scene, {0.8f, 0.8f, 0.8f});
  const uint32_t light = add_material(scene, {0, 0, 0}, {20, 20, 20});
  const float t = 0.005f;  // wall thickness
  add_inward_box(scene, {0, 0, 0}, {2, 2, 2}, white);        // left room, x in [0, 2]
  add_inward_box(scene, {2 + t, 0, 0}, {4 + t, 2, 2}, white);  // right room, x in [2+t, 4+t]
  add_quad(scene, {0.5f, 1.99f, 0.5f}, {1, 0, 0}, {0, 0, 1}, light);
  TexelGBuffer gbuffer;
  // Right-room texels hugging the shared wall, on the floor and on the wall itself.
  for (int i = 0; i < 16; ++i) {
    const float z = 0.1f + 0.12f * float(i);
    gbuffer.texels.push_back(texel_at({2 + t + 0.01f, 0, z}, {0, 1, 0}));
    gbuffer.texels.push_back(texel_at({2 + t, 0.05f + 0.12f * float(i), 1.0f}, {1, 0, 0}));
  }
  IntegratorSettings settings;
  settings.spp = 128;
  const LightmapEstimate e = bake_scene(scene, gbuffer, settings);
  expect_finite(e);
  double leak = 0;
  for (size_t i = 0; i < e.texels.size(); ++i) leak = std::max(leak, double(luminance(e.mean_total(i))));
  std::printf("[stress %s] thin wall (t = %.3g): largest E/pi in the dark room %.3g\n", GetParam().c_str(), t, leak);
  EXPECT_EQ(leak, 0.0);
}

INSTANTIATE_TEST_SUITE_P(Backends, Stress, ::testing::Values("cpu", "cpu_guided", "cpu_svo_guided", "vulkan", "vulkan_guided",
                                           "vulkan_svo_guided"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
}  // namespace exitance
