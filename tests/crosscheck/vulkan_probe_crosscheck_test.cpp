// Light probes on the Vulkan backend against the CPU reference (DESIGN §6.2) and the closed forms.
// Each probe position is baked as R "copies" (R probes at the same place: independent random
// streams), so one bake gives R independent estimates per position and the standard error comes
// from their spread. Per position and SH coefficient (and channel) a z-test with the SEs of both
// backends (independent seeds) catches bias; back-face counts are compared as proportions. Every
// test runs with VK_LAYER_KHRONOS_validation and fails on any message. Without a Vulkan device, SKIP.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "exitance/bake/command/prepared_scene.h"
#include "exitance/common/sampling.h"
#include "exitance/runtime/spherical_harmonics.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "support/analytic_scenes.h"
#include "support/image_sky_scene.h"
#include "support/independent_estimates.h"
#include "support/textured_scenes.h"
#include "support/validated_vulkan_backend.h"

namespace exitance {
namespace {

using testing::AnalyticScene;

constexpr double kZLimit = 4.0;
constexpr int kCopies = 32;

std::vector<Vec3> with_copies(const std::vector<Vec3>& positions) {
  std::vector<Vec3> probes;
  for (const Vec3& p : positions)
    for (int r = 0; r < kCopies; ++r) probes.push_back(p);
  return probes;
}

// Mean and standard error over the copies of position `p` of quantity(SH of one copy).
using Summary = testing::MeanAndError;

template <typename F>
Summary summarise(const ProbeEstimate& e, size_t position, F quantity) {
  std::vector<double> values;
  for (int r = 0; r < kCopies; ++r) values.push_back(quantity(e.mean(position * kCopies + size_t(r))));
  return testing::mean_and_standard_error(values);
}

void expect_sane(const ProbeEstimate& e, size_t probes, uint32_t spp, const char* what) {
  ASSERT_EQ(e.sh_sum.size(), probes) << what;
  ASSERT_EQ(e.samples.size(), probes) << what;
  ASSERT_EQ(e.backface_hits.size(), probes) << what;
  for (size_t i = 0; i < probes; ++i) EXPECT_EQ(e.samples[i], spp) << what << " probe " << i;
  EXPECT_EQ(e.nonfinite_samples, 0u) << what;
  EXPECT_GT(e.rays, 0u) << what;
}

struct Comparison {
  double worst_z = 0;
  double worst_backface_z = 0;
};

// Both backends with independent seeds; z-test per position, coefficient and channel, and on the
// proportion of back-face hits per position.
void compare_backends(const Scene& scene, const std::vector<Vec3>& positions, IntegratorSettings settings,
                      const char* what) {
  Comparison c;
  CREATE_VULKAN_OR_SKIP(vk, scene);
  const std::vector<Vec3> probes = with_copies(positions);
  settings.seed = 1001;
  const ProbeEstimate gpu = vk->bake_probes(probes, settings);
  settings.seed = 2002;
  const ProbeEstimate cpu = CpuReferenceIntegrator(scene).bake_probes(probes, settings);
  expect_sane(gpu, probes.size(), settings.spp, what);
  expect_sane(cpu, probes.size(), settings.spp, what);
  if (::testing::Test::HasFatalFailure()) return;
  for (size_t p = 0; p < positions.size(); ++p) {
    for (int k = 0; k < kShCoefficients; ++k)
      for (int ch = 0; ch < 3; ++ch) {
        auto coefficient = [&](const ShRgb& sh) { return double(sh[size_t(k)][ch]); };
        const Summary a = summarise(gpu, p, coefficient), b = summarise(cpu, p, coefficient);
        const double diff = std::fabs(a.mean - b.mean), se = std::hypot(a.standard_error, b.standard_error);
        if (diff <= 1e-5 * std::fabs(b.mean) + 1e-9) continue;  // deterministic cases: rounding only
        const double z = se > 0 ? diff / se : INFINITY;
        c.worst_z = std::max(c.worst_z, z);
        EXPECT_LT(z, kZLimit) << what << ": position " << p << " coefficient " << k << " channel " << ch << " gpu "
                              << a.mean << " cpu " << b.mean << " SE " << se;
      }
    uint64_t hits_gpu = 0, hits_cpu = 0, n = 0;
    for (int r = 0; r < kCopies; ++r) {
      hits_gpu += gpu.backface_hits[p * kCopies + size_t(r)];
      hits_cpu += cpu.backface_hits[p * kCopies + size_t(r)];
      n += settings.spp;
    }
    // Binomial SE of the difference of two proportions (conservative: the directions are stratified).
    const double fg = double(hits_gpu) / double(n), fc = double(hits_cpu) / double(n), f = 0.5 * (fg + fc);
    const double se = std::sqrt(std::max(f * (1 - f), 0.25 / double(n)) * 2.0 / double(n));
    const double z = std::fabs(fg - fc) / se;
    c.worst_backface_z = std::max(c.worst_backface_z, z);
    EXPECT_LT(z, kZLimit) << what << ": back-face fraction at position " << p << " gpu " << fg << " cpu " << fc;
  }
  // Same estimator, same path lengths: the ray counts agree to well under a percent at these sizes.
  EXPECT_NEAR(double(gpu.rays) / double(cpu.rays), 1.0, 0.02) << what << ": rays gpu " << gpu.rays << " cpu " << cpu.rays;
  std::printf("[probe crosscheck] %-26s positions %zu x %d copies x %u spp: worst |z| %.2f, back faces %.2f; "
              "rays gpu %llu cpu %llu, seconds gpu %.2f cpu %.2f\n",
              what, positions.size(), kCopies, settings.spp, c.worst_z, c.worst_backface_z,
              (unsigned long long)gpu.rays, (unsigned long long)cpu.rays, gpu.seconds, cpu.seconds);
}

// Inside the white furnace every direction carries Le/(1 - rho): E/pi = Le/(1 - rho) for any
// normal. With the bounces after the hit limited to m, the probe reads Le (1 + rho + ... + rho^(m+1)).
void furnace_closed_form(int max_bounces, double expected_factor, const char* what) {
  const float albedo = 0.5f;
  const AnalyticScene a = testing::white_furnace(albedo);
  CREATE_VULKAN_OR_SKIP(vk, a.scene);
  const std::vector<Vec3> positions = {{0.5f, 0.5f, 0.5f}, {0.2f, 0.8f, 0.3f}, {0.9f, 0.1f, 0.6f}};
  IntegratorSettings settings;
  settings.spp = 256;
  settings.seed = 7;
  settings.max_bounces = max_bounces;
  const ProbeEstimate e = vk->bake_probes(with_copies(positions), settings);
  expect_sane(e, positions.size() * kCopies, settings.spp, what);
  if (::testing::Test::HasFatalFailure()) return;
  const Vec3 normals[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  double worst = 0;
  for (size_t p = 0; p < positions.size(); ++p) {
    EXPECT_EQ(e.backface_hits[p * kCopies], 0u);
    for (const Vec3& n : normals)
      for (int ch = 0; ch < 3; ++ch) {
        const Summary s = summarise(e, p, [&](const ShRgb& sh) { return double(sh_irradiance_over_pi(sh, n)[ch]); });
        const double exact = a.colour[ch] * expected_factor;
        const double z = (s.mean - exact) / s.standard_error;
        worst = std::max(worst, std::fabs(z));
        EXPECT_LE(std::fabs(s.mean - exact), kZLimit * s.standard_error + 1e-5 * exact)
            << what << ": position " << p << " normal (" << n.x << ", " << n.y << ", " << n.z << ") channel " << ch
            << " estimate " << s.mean << " exact " << exact << " SE " << s.standard_error;
        EXPECT_LT(s.standard_error, 0.01 * exact) << "standard error implausibly large";
      }
  }
  std::printf("[probe crosscheck] %-26s E/pi for 6 normals at %zu positions: worst |z| %.2f\n", what,
              positions.size(), worst);
}

TEST(VulkanProbeCrosscheck, WhiteFurnaceProbesReadLeOverOneMinusRho) {
  furnace_closed_form(-1, 1.0 / (1.0 - 0.5), "furnace rho 0.5");
}

// max_bounces counts from the probe ray's hit: 1 -> Le (1 + rho + rho^2).
TEST(VulkanProbeCrosscheck, WhiteFurnaceBounceLimitCountsFromTheHit) {
  furnace_closed_form(1, 1.0 + 0.5 + 0.25, "furnace max_bounces 1");
}

TEST(VulkanProbeCrosscheck, WhiteFurnaceAgainstReference) {
  const AnalyticScene a = testing::white_furnace(0.5f);
  IntegratorSettings settings;
  settings.spp = 300;  // a full stratified set of 256 and a partial one of 44
  // The second position lies just outside the box: about half its rays hit back faces.
  compare_backends(a.scene, {{0.5f, 0.5f, 0.5f}, {0.3f, 0.7f, 0.2f}, {0.5f, 0.5f, -0.001f}}, settings, "furnace");
}

// Same seed, same sample streams: both backends trace the same paths up to floating-point rounding
// (ray directions from cos/sin, which may differ in the last bit and on rare occasions change a hit
// or a roulette decision), so the sums agree far more tightly than the statistical error.
TEST(VulkanProbeCrosscheck, SameSeedMatchesReferenceSampleForSample) {
  const AnalyticScene a = testing::white_furnace(0.5f);
  CREATE_VULKAN_OR_SKIP(vk, a.scene);
  const std::vector<Vec3> probes = {{0.5f, 0.5f, 0.5f}, {0.2f, 0.8f, 0.3f}, {0.5f, 0.5f, -0.001f}};
  IntegratorSettings settings;
  settings.spp = 256;
  settings.seed = 42;
  settings.russian_roulette_start = 2;  // roulette from the second bounce after the hit: depths must line up
  const ProbeEstimate gpu = vk->bake_probes(probes, settings);
  const ProbeEstimate cpu = CpuReferenceIntegrator(a.scene).bake_probes(probes, settings);
  double worst = 0;
  for (size_t i = 0; i < probes.size(); ++i) {
    EXPECT_EQ(gpu.backface_hits[i], cpu.backface_hits[i]);
    EXPECT_EQ(gpu.samples[i], cpu.samples[i]);
    for (size_t j = 0; j < 27; ++j) {
      const double scale = std::fabs(cpu.sh_sum[i][0]) + 1e-9;  // relative to the DC term
      worst = std::max(worst, std::fabs(gpu.sh_sum[i][j] - cpu.sh_sum[i][j]) / scale);
    }
  }
  std::printf("[probe crosscheck] same seed: worst |gpu - cpu| / c00 %.3g, rays gpu %llu cpu %llu\n", worst,
              (unsigned long long)gpu.rays, (unsigned long long)cpu.rays);
  EXPECT_LT(worst, 1e-3);
  const double ray_ratio = double(gpu.rays) / double(cpu.rays);
  EXPECT_NEAR(ray_ratio, 1.0, 1e-3);
}

// Probes and lightmaps share one integrator (buffers are reused): interleaved bakes give the same
// results, bit for bit, as the first ones with the same seed.
TEST(VulkanProbeCrosscheck, InterleavedWithLightmapBakesAndDeterministic) {
  const AnalyticScene a = testing::white_furnace(0.5f);
  CREATE_VULKAN_OR_SKIP(vk, a.scene);
  IntegratorSettings settings;
  settings.spp = 64;
  settings.seed = 9;
  const std::vector<Vec3> probes = {{0.5f, 0.5f, 0.5f}, {0.1f, 0.2f, 0.3f}, {0.5f, 0.5f, -0.001f}};
  const LightmapEstimate lightmap = vk->bake(a.gbuffer, settings);
  const ProbeEstimate first = vk->bake_probes(probes, settings);
  const LightmapEstimate lightmap_again = vk->bake(a.gbuffer, settings);
  const ProbeEstimate again = vk->bake_probes(probes, settings);
  for (size_t i = 0; i < a.gbuffer.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(lightmap.texels[i].total[c], lightmap_again.texels[i].total[c]);
  EXPECT_EQ(lightmap.rays, lightmap_again.rays);
  for (size_t i = 0; i < probes.size(); ++i) {
    EXPECT_EQ(first.sh_sum[i], again.sh_sum[i]);
    EXPECT_EQ(first.backface_hits[i], again.backface_hits[i]);
  }
  EXPECT_EQ(first.rays, again.rays);
  // Many more probes than texels: the probe buffers grow, the lightmap is unaffected.
  std::vector<Vec3> many;
  for (Vec2 p : testing::grid_points(24, 0.05f)) many.push_back({p.x, 0.5f, p.y});
  settings.spp = 4;
  const ProbeEstimate grid = vk->bake_probes(many, settings);
  for (uint32_t n : grid.samples) EXPECT_EQ(n, 4u);
  settings.spp = 64;
  const LightmapEstimate after_grid = vk->bake(a.gbuffer, settings);
  for (size_t i = 0; i < a.gbuffer.texels.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(lightmap.texels[i].total[c], after_grid.texels[i].total[c]);
  // Whatever the batch cut: 64 path slots (256 work items a batch) split the grid into chunks of
  // probes and the samples into passes; every probe's sums are the same, bit for bit.
  CREATE_VULKAN_OR_SKIP(small, a.scene, 64u);
  settings.spp = 4;
  const ProbeEstimate cut = small->bake_probes(many, settings);
  for (size_t i = 0; i < many.size(); ++i) ASSERT_EQ(cut.sh_sum[i], grid.sh_sum[i]) << "probe " << i;
  EXPECT_EQ(cut.rays, grid.rays);
  settings.spp = 300;
  const ProbeEstimate passes = small->bake_probes(probes, settings);
  const ProbeEstimate one_pass = vk->bake_probes(probes, settings);
  for (size_t i = 0; i < probes.size(); ++i) EXPECT_EQ(passes.sh_sum[i], one_pass.sh_sum[i]) << "probe " << i;
}

// Probes above (and one below: back faces) a grey plane under a constant sky.
TEST(VulkanProbeCrosscheck, SkyAndPlaneAgainstReference) {
  const AnalyticScene a = testing::plane_under_constant_sky();
  IntegratorSettings settings;
  settings.spp = 256;
  compare_backends(a.scene, {{0, 0.05f, 0}, {0.5f, 0.5f, -0.3f}, {-0.8f, 2.0f, 0.9f}, {0.2f, -0.3f, 0.1f}}, settings,
                   "sky + plane");
}

// A probe above a black plane sees only the sky: c00 = L sqrt(pi) (green sky 1), no variance from
// the plane; the Vulkan estimate must match the closed form of probe_lighting_test.cpp.
TEST(VulkanProbeCrosscheck, SkyAbovePlaneClosedForm) {
  Scene scene;
  const float half = 1000.0f;
  testing::add_quad(scene, {-half, 0, half}, {2 * half, 0, 0}, {0, 0, -2 * half}, testing::add_material(scene, {0, 0, 0}));
  scene.sky.constant = {0.5f, 1.0f, 2.0f};
  CREATE_VULKAN_OR_SKIP(vk, scene);
  IntegratorSettings settings;
  settings.spp = 256;
  settings.seed = 3;
  const std::vector<Vec3> positions = {{0, 1, 0}};
  const ProbeEstimate e = vk->bake_probes(with_copies(positions), settings);
  expect_sane(e, kCopies, settings.spp, "black plane");
  if (::testing::Test::HasFatalFailure()) return;
  const Summary c00 = summarise(e, 0, [](const ShRgb& sh) { return double(sh[0][1]); });
  const Summary up = summarise(e, 0, [](const ShRgb& sh) { return double(sh_irradiance_over_pi(sh, {0, 1, 0})[2]); });
  EXPECT_LE(std::fabs(c00.mean - std::sqrt(kPi)), kZLimit * c00.standard_error + 1e-4);
  EXPECT_LE(std::fabs(up.mean - 2.0), kZLimit * up.standard_error + 1e-4);
  std::printf("[probe crosscheck] black plane: c00 %.5f (exact %.5f, SE %.2g), E/pi up %.5f (exact 2, SE %.2g)\n",
              c00.mean, std::sqrt(kPi), c00.standard_error, up.mean, up.standard_error);
}

// Probe rays that escape read the image sky (environment_map.h on both backends): above, beside and
// below the tilted black quads against the reference, and from a free point (the quads subtend
// ~1e-6 sr) c00 = Y00 * integral of the sky's radiance.
TEST(VulkanProbeCrosscheck, ImageSkyAgainstReferenceAndClosedForm) {
  const testing::ImageSkyScene s = testing::image_sky_over_tilted_quads();
  IntegratorSettings settings;
  settings.spp = 256;
  compare_backends(s.scene, {{0.1f, 0.3f, 0.0f}, {0.3f, 0.1f, 1000.0f}, {0.0f, -0.4f, 3000.0f}}, settings, "image sky");
  CREATE_VULKAN_OR_SKIP(vk, s.scene);
  settings.seed = 4;
  settings.spp = 1024;
  const ProbeEstimate e = vk->bake_probes(with_copies({{0, 0, 500}}), settings);
  expect_sane(e, kCopies, settings.spp, "image sky, free probe");
  if (::testing::Test::HasFatalFailure()) return;
  for (int c = 0; c < 3; ++c) {
    const Summary c00 = summarise(e, 0, [&](const ShRgb& sh) { return double(sh[0][c]); });
    EXPECT_LE(std::fabs(c00.mean - s.probe_c00[c]), kZLimit * c00.standard_error + 1e-5 * s.probe_c00[c])
        << "channel " << c << " c00 " << c00.mean << " exact " << s.probe_c00[c] << " SE " << c00.standard_error;
    std::printf("[probe crosscheck] image sky, free probe: channel %d c00 %.5f (exact %.5f, SE %.2g)\n", c, c00.mean,
                s.probe_c00[c], c00.standard_error);
  }
}

TEST(VulkanProbeCrosscheck, PunctualLightsAgainstReference) {
  IntegratorSettings settings;
  settings.spp = 256;
  const std::vector<Vec3> positions = {{0.2f, 0.5f, -0.1f}, {1.5f, 1.0f, 1.0f}, {0.0f, -0.5f, 0.0f}};
  compare_backends(testing::point_light_over_plane().scene, positions, settings, "point light");
  compare_backends(testing::directional_light_on_plane().scene, positions, settings, "directional light");
  // The spot scene's plane is black: add grey to it so the probes see light it reflects.
  AnalyticScene spot = testing::spot_light_cone_edges();
  spot.scene.materials[0].base_color = {0.6f, 0.6f, 0.6f};
  compare_backends(spot.scene, positions, settings, "spot light");
}

PreparedScene load_sample(const std::string& name, const std::string& sky) {
  Diagnostics diagnostics;
  AtlasSettings atlas;
  atlas.texel_density = 1.0f;  // the probes do not use the lightmap
  return prepare_scene_for_lighting(std::string(EXITANCE_SAMPLE_DIR) + "/" + name + ".gltf", sky, atlas, diagnostics);
}

// Probes in the 4 m Cornell room: centre-back, low front-left, under the light, 1 cm above the
// floor in a corner, and one inside the tall box (its faces point outward: back faces above, the
// floor below).
// Textures, COLOR_0, an emissive texture, MASK and BLEND (traversal of probe rays and the paths after).
TEST(VulkanProbeCrosscheck, TexturedMaskedVertexColouredScene) {
  const testing::TexturedScene t = testing::textured_masked_scene();
  IntegratorSettings settings;
  settings.spp = 256;
  compare_backends(t.scene, t.probes, settings, "textured scene");
}

TEST(VulkanProbeCrosscheck, CornellRoom) {
  PreparedScene s = load_sample("cornell_room", "");
  const std::vector<Vec3> positions = {
      {1.2f, 2.5f, -1.2f}, {-1.5f, 1.0f, 1.3f}, {0.0f, 3.5f, 0.0f}, {1.5f, 0.01f, -1.5f}, {-0.7f, 1.0f, -0.6f}};
  IntegratorSettings settings;
  settings.spp = 512;  // the copies' means are skewed by the bright light at low spp; 512 keeps the SEs honest
  compare_backends(s.scene, positions, settings, "cornell_room");
  settings.max_bounces = 1;
  compare_backends(s.scene, positions, settings, "cornell_room max_bounces 1");
}

// A time budget stops only between complete stratified sets; progress is reported.
TEST(VulkanProbeCrosscheck, TimeBudgetStopsOnCompleteSets) {
  const AnalyticScene a = testing::white_furnace(0.5f);
  CREATE_VULKAN_OR_SKIP(vk, a.scene);
  IntegratorSettings settings;
  settings.spp = 0;
  settings.time_budget_seconds = 1e-6;
  int calls = 0;
  settings.progress = [&](double, uint64_t) { ++calls; };
  const ProbeEstimate e = vk->bake_probes({{0.5f, 0.5f, 0.5f}, {0.1f, 0.2f, 0.3f}}, settings);
  EXPECT_GT(calls, 0);
  for (uint32_t n : e.samples) {
    EXPECT_GT(n, 0u);
    EXPECT_EQ(n % kProbeStratifiedSetSize, 0u);
  }
  EXPECT_EQ(e.samples[0], e.samples[1]);
  settings.time_budget_seconds = 0;
  EXPECT_THROW(vk->bake_probes({{0.5f, 0.5f, 0.5f}}, settings), std::invalid_argument);
  EXPECT_TRUE(vk->bake_probes({}, IntegratorSettings{}).samples.empty());
}

}  // namespace
}  // namespace exitance
