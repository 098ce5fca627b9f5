// Cross-backend checks (DESIGN §6.2): the Vulkan wavefront path tracer against the CPU reference on
// the analytic scenes and two sample scenes. Per region of texels, a z-test with the variances of
// both estimators (|z| < 4) catches real bias; relMSE between the two converged results < 0.5 %
// catches gross errors; deterministic cases are also checked against the closed forms. Every test
// runs with VK_LAYER_KHRONOS_validation and fails on any message. Without a Vulkan device, SKIP.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "exitance/bake/command/prepared_scene.h"
#include "exitance/common/sampling.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "support/analytic_scenes.h"
#include "support/lightmap_comparison.h"
#include "support/validated_vulkan_backend.h"

namespace exitance {
namespace {

using testing::AnalyticScene;
using testing::add_inward_box;
using testing::add_material;
using testing::add_quad;
using testing::grid_points;
using testing::texel_at;

using testing::Comparison;
using testing::compare_estimates;

LightmapEstimate cpu_bake(const Scene& scene, const TexelGBuffer& g, IntegratorSettings s, uint64_t seed) {
  s.seed = seed;
  return CpuReferenceIntegrator(scene).bake(g, s);
}

// Runs both backends with independent seeds and checks agreement.
void crosscheck(const Scene& scene, const TexelGBuffer& g, IntegratorSettings settings, size_t group, double max_rel_mse,
                const char* what, LightmapEstimate* gpu_out = nullptr) {
  CREATE_VULKAN_OR_SKIP(vk, scene);
  settings.seed = 1001;
  const LightmapEstimate gpu = vk->bake(g, settings);
  const LightmapEstimate cpu = cpu_bake(scene, g, settings, 2002);
  const Comparison c = compare_estimates(gpu, cpu, group, what);
  EXPECT_LT(c.rel_mse, max_rel_mse) << what;
  // Bounce layers sum to the total wherever no path went deeper than the recorded layers.
  if (gpu_out) *gpu_out = gpu;
}

void furnace(float albedo, uint32_t spp) {
  const AnalyticScene a = testing::white_furnace(albedo);
  const TexelGBuffer& g = a.gbuffer;
  IntegratorSettings s;
  s.spp = spp;
  LightmapEstimate gpu;
  crosscheck(a.scene, g, s, 16, 0.005, albedo < 0.7f ? "furnace rho 0.5" : "furnace rho 0.9", &gpu);
  if (gpu.texels.empty()) return;
  // Against the closed form Le / (1 - rho) over all texels.
  for (int c = 0; c < 3; ++c) {
    double mean = 0, var = 0;
    for (size_t i = 0; i < g.texels.size(); ++i) mean += gpu.mean_total(i)[c], var += gpu.variance_of_mean(i)[c];
    mean /= double(g.texels.size());
    const double se = std::sqrt(var) / double(g.texels.size()), exact = a.colour[c] * a.exact[0];
    EXPECT_LT(std::fabs(mean - exact), 4 * se) << "channel " << c << " mean " << mean << " exact " << exact;
  }
}

TEST(VulkanCrosscheck, WhiteFurnaceAlbedoHalf) { furnace(0.5f, 512); }
TEST(VulkanCrosscheck, WhiteFurnaceAlbedoPointNine) { furnace(0.9f, 1024); }

TEST(VulkanCrosscheck, PlaneUnderConstantSkyIsExact) {
  const AnalyticScene a = testing::plane_under_constant_sky();
  IntegratorSettings s;
  s.spp = 16;
  LightmapEstimate gpu;
  crosscheck(a.scene, a.gbuffer, s, 8, 1e-6, "plane under constant sky", &gpu);
  for (size_t i = 0; i < gpu.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(gpu.mean_total(i)[c], a.colour[c], 1e-5 * a.colour[c]);
}

TEST(VulkanCrosscheck, PointLightIsExact) {
  const AnalyticScene a = testing::point_light_over_plane();
  IntegratorSettings s;
  s.spp = 4;
  LightmapEstimate gpu;
  crosscheck(a.scene, a.gbuffer, s, 6, 1e-6, "point light", &gpu);
  for (size_t i = 0; i < gpu.texels.size(); ++i) {
    EXPECT_NEAR(gpu.mean_total(i).x, a.exact[i], 1e-5 * a.exact[i]);
    EXPECT_NEAR(gpu.mean_total(i).y, 2 * a.exact[i], 2e-5 * a.exact[i]);
  }
}

TEST(VulkanCrosscheck, SpotLightIsExact) {
  const AnalyticScene a = testing::spot_light_cone_edges();
  IntegratorSettings s;
  s.spp = 2;
  LightmapEstimate gpu;
  crosscheck(a.scene, a.gbuffer, s, 4, 1e-6, "spot light", &gpu);
  for (size_t i = 0; i < gpu.texels.size(); ++i) EXPECT_NEAR(gpu.mean_total(i).x, a.exact[i], 1e-5 * a.exact[i] + 1e-9);
  if (!gpu.texels.empty()) EXPECT_EQ(gpu.mean_total(a.gbuffer.texels.size() - 1).x, 0.0f);
}

TEST(VulkanCrosscheck, DirectionalLightIsExact) {
  const AnalyticScene a = testing::directional_light_on_plane();
  IntegratorSettings s;
  s.spp = 4;
  LightmapEstimate gpu;
  crosscheck(a.scene, a.gbuffer, s, 4, 1e-6, "directional light", &gpu);
  for (size_t i = 0; i < gpu.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double exact = a.colour[c] * a.exact[i];
      EXPECT_NEAR(gpu.mean_total(i)[c], exact, 1e-5 * exact);
    }
}

TEST(VulkanCrosscheck, TwoParallelUnitSquares) {
  const AnalyticScene a = testing::two_parallel_unit_squares();
  IntegratorSettings s;
  s.spp = 512;
  crosscheck(a.scene, a.gbuffer, s, 8, 0.005, "parallel unit squares");
}

TEST(VulkanCrosscheck, AlbedoZeroHasNoIndirectEnergy) {
  const AnalyticScene a = testing::albedo_zero_room();
  IntegratorSettings s;
  s.spp = 256;
  s.recorded_bounces = 3;
  LightmapEstimate gpu;
  crosscheck(a.scene, a.gbuffer, s, 8, 0.005, "albedo zero", &gpu);
  for (size_t i = 0; i < gpu.texels.size(); ++i) {
    EXPECT_GT(gpu.mean_total(i).x, 0.0f);
    EXPECT_FLOAT_EQ(gpu.mean_total(i).x, gpu.mean_direct(i).x);
    EXPECT_EQ(gpu.mean_bounce(1, i).x, 0.0f);
    EXPECT_EQ(gpu.mean_bounce(2, i).x, 0.0f);
  }
}

// Same seed, same results (bit for bit), whatever the batch cut; bounce layers add up.
TEST(VulkanCrosscheck, DeterministicPerSeedAndProgressReported) {
  Scene scene;
  add_inward_box(scene, {0, 0, 0}, {1, 1, 1}, add_material(scene, {0.6f, 0.6f, 0.6f}, {1, 1, 1}));
  TexelGBuffer g;
  for (Vec2 p : grid_points(4, 0.1f)) g.texels.push_back(texel_at({p.x, 0.0f, p.y}, {0, 1, 0}));
  CREATE_VULKAN_OR_SKIP(vk, scene);
  IntegratorSettings s;
  s.spp = 32;
  s.seed = 5;
  int calls = 0;
  s.progress = [&](double, uint64_t) { ++calls; };
  const LightmapEstimate a = vk->bake(g, s);
  const LightmapEstimate b = vk->bake(g, s);
  EXPECT_GT(calls, 0);
  for (size_t i = 0; i < g.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(a.texels[i].total[c], b.texels[i].total[c]);
      EXPECT_EQ(a.texels[i].total_squared[c], b.texels[i].total_squared[c]);
    }
  EXPECT_EQ(a.rays, b.rays);
}

TEST(VulkanCrosscheck, UnsupportedScenesAreRefused) {
  Scene scene;
  add_quad(scene, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}, add_material(scene, {1, 1, 1}));
  scene.sky.environment.width = scene.sky.environment.height = 1;
  scene.sky.environment.rgb = {1, 1, 1};
  EXPECT_THROW(VulkanIntegrator::create(make_lighting_scene(scene)), std::runtime_error);
  scene.sky.environment = {};
  scene.textures.push_back(scene.sky.environment);
  scene.materials[0].base_color_texture.texture = 0;
  EXPECT_THROW(VulkanIntegrator::create(make_lighting_scene(scene)), std::runtime_error);
}

TEST(VulkanCrosscheck, DeviceEnumeration) {
  const std::vector<VulkanDeviceInfo> devices = enumerate_vulkan_devices();
  if (devices.empty()) GTEST_SKIP() << "no Vulkan device";
  for (const VulkanDeviceInfo& d : devices) {
    EXPECT_FALSE(d.name.empty());
    std::printf("[crosscheck] device %u: %s (%s)%s\n", d.index, d.name.c_str(), to_string(d.type),
                d.usable ? "" : (" unusable: " + d.missing_feature).c_str());
  }
}

// A sample scene through the offline stage at a low texel density.
PreparedScene load_sample(const std::string& name, const std::string& sky, float density) {
  Diagnostics diagnostics;
  AtlasSettings atlas;
  atlas.texel_density = density;
  return prepare_scene_for_lighting(std::string(EXITANCE_SAMPLE_DIR) + "/" + name + ".gltf", sky, atlas, diagnostics);
}

TEST(VulkanCrosscheck, CornellRoom) {
  PreparedScene s = load_sample("cornell_room", "", 2.0f);
  ASSERT_GT(s.gbuffer.texels.size(), 50u);
  IntegratorSettings settings;
  settings.spp = 1024;
  crosscheck(s.scene, s.gbuffer, settings, 32, 0.005, "cornell_room");
}

TEST(VulkanCrosscheck, CourtyardUnderConstantSky) {
  PreparedScene s = load_sample("courtyard", "0.6,0.7,1.0", 0.5f);
  ASSERT_GT(s.gbuffer.texels.size(), 50u);
  IntegratorSettings settings;
  settings.spp = 256;
  crosscheck(s.scene, s.gbuffer, settings, 32, 0.005, "courtyard");
}

}  // namespace
}  // namespace exitance

namespace exitance {
namespace {

// --directional sh1 (issue 14): both backends with the defensive first continuation and L1 sums.
// E/pi as every crosscheck; each L1 coefficient per region of `group` texels: the mean of the
// per-texel differences GPU - CPU (each of expectation 0) within 4 standard errors from their
// sample variance.
void crosscheck_directional(const Scene& scene, const TexelGBuffer& g, uint32_t spp, size_t group, const char* what) {
  CREATE_VULKAN_OR_SKIP(vk, scene);
  IntegratorSettings settings;
  settings.spp = spp;
  settings.directional = DirectionalMode::Sh1;
  settings.seed = 1001;
  const LightmapEstimate gpu = vk->bake(g, settings);
  const LightmapEstimate cpu = cpu_bake(scene, g, settings, 2002);
  ASSERT_TRUE(gpu.has_sh1());
  ASSERT_TRUE(cpu.has_sh1());
  EXPECT_EQ(gpu.nonfinite_samples, 0u);
  const Comparison c = compare_estimates(gpu, cpu, group, what);
  EXPECT_LT(c.rel_mse, 0.005) << what;
  double worst = 0;
  for (size_t begin = 0; begin + group <= g.texels.size(); begin += group)
    for (int axis = 0; axis < 3; ++axis)
      for (int ch = 0; ch < 3; ++ch) {
        double sum = 0, squares = 0;
        for (size_t i = begin; i < begin + group; ++i) {
          const double d = double(gpu.mean_sh1(axis, i)[ch]) - double(cpu.mean_sh1(axis, i)[ch]);
          sum += d, squares += d * d;
        }
        const double n = double(group), mean = sum / n;
        const double se = std::sqrt(std::max(0.0, squares / n - mean * mean) / (n - 1));
        const double z = se > 0 ? mean / se : (mean == 0 ? 0 : 1e9);
        worst = std::max(worst, std::fabs(z));
        EXPECT_LT(std::fabs(z), 4.0) << what << " texels " << begin << "+" << group << " L1 axis " << axis << " channel "
                                     << ch << ": mean GPU - CPU " << mean << " SE " << se;
      }
  std::printf("[crosscheck] %s directional sh1: E/pi relMSE %.3g, largest L1 region |z| %.2f\n", what, c.rel_mse, worst);
}

TEST(VulkanCrosscheck, DirectionalSh1CornellRoom) {
  PreparedScene s = load_sample("cornell_room", "", 2.0f);
  ASSERT_GT(s.gbuffer.texels.size(), 50u);
  crosscheck_directional(s.scene, s.gbuffer, 1024, 32, "cornell_room");
}

TEST(VulkanCrosscheck, DirectionalSh1EmittingSquare) {
  const AnalyticScene a = testing::two_parallel_unit_squares();
  crosscheck_directional(a.scene, a.gbuffer, 256, 16, "emitting square");
}

}  // namespace
}  // namespace exitance
