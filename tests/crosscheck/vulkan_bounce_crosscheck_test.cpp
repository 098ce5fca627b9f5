// The per-bounce mode (IntegratorMode::Bounces, issue 10) on the Vulkan backend: the furnace's
// closed forms per bounce layer and with the completed tail, and every bounce layer of the Cornell
// room per region against the CPU reference. Validation layers on; without a Vulkan device, SKIP.
//
// Standard errors come from independent seeds on each side: a layer reads the layer below through
// a shared cache, so the texels' errors are correlated and the tracked per-texel variance does not
// add up to the variance of a region's mean (tests/analytic/per_bounce_test.cpp does the same).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <vector>

#include "exitance/bake/command/prepared_scene.h"
#include "exitance/common/gpu_layout.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "support/analytic_scenes.h"
#include "support/atlas_box.h"
#include "support/independent_estimates.h"
#include "support/lightmap_comparison.h"
#include "support/test_scenes.h"
#include "support/validated_vulkan_backend.h"

namespace exitance {
namespace {

// Two-sided. Per-region tests compare two 8-seed means (Welch's t with ~14 degrees of freedom):
// P(|t| > 5) ~ 2e-4 per test, under 1 % over the Cornell room's 28 region-layer tests. The furnace
// tests one 8-seed mean against an exact value (t with 7 dof): P(|t| > 5) ~ 2e-3 per test.
constexpr double kZLimit = 5.0;
constexpr int kSeeds = 8;

IntegratorSettings bounce_settings(uint32_t spp, uint64_t seed, int max_bounces) {
  IntegratorSettings s;
  s.integrator = IntegratorMode::Bounces;
  s.spp = spp;
  s.seed = seed;
  s.max_bounces = max_bounces;
  return s;
}

double mean_layer_over_texels(const LightmapEstimate& e, int layer, int channel) {
  double sum = 0;
  for (size_t i = 0; i < e.texels.size(); ++i) sum += e.mean_bounce(layer, i)[channel];
  return sum / double(e.texels.size());
}

// Furnace of albedo rho, emission Le everywhere, on a real atlas: B_k = rho^k Le exactly in every
// texel (the field is constant, so the cache lookup carries no resolution bias).
TEST(VulkanPerBounce, FurnaceLayersAreAlbedoPowersOfTheEmission) {
  const float rho = 0.5f;
  const Vec3 le{1.0f, 0.5f, 0.25f};
  const Vec3 emission[6] = {le, le, le, le, le, le};
  const testing::AtlasScene box = testing::atlas_box(rho, emission, 8);
  CREATE_VULKAN_OR_SKIP(vk, box.scene);
  const int bounces = 6;
  std::vector<LightmapEstimate> runs;
  for (int seed = 0; seed < kSeeds; ++seed) {
    runs.push_back(vk->bake(box.gbuffer, bounce_settings(8, uint64_t(seed), bounces)));
    const LightmapEstimate& e = runs.back();
    ASSERT_EQ(e.recorded_bounces, bounces + 1);
    EXPECT_EQ(e.bounce_statistics.bounces, bounces);
    EXPECT_EQ(e.bounce_statistics.texelless_hits, 0u) << "a closed box: every gather hit has texels";
    EXPECT_GT(e.bounce_statistics.gathers, 0u);
    EXPECT_EQ(e.nonfinite_samples, 0u);
  }
  for (int k = 0; k <= bounces; ++k)
    for (int c = 0; c < 3; ++c) {
      std::vector<double> ratios;
      const double exact = le[c] * std::pow(double(rho), k);
      for (const LightmapEstimate& e : runs) ratios.push_back(mean_layer_over_texels(e, k, c) / exact);
      const testing::MeanAndError s = testing::mean_and_standard_error(ratios);
      std::printf("[vulkan per-bounce] furnace rho 0.5 B_%d ch%d: estimate/exact %.5f SE %.2g\n", k, c, s.mean,
                  s.standard_error);
      EXPECT_LE(std::fabs(s.mean - 1), kZLimit * s.standard_error + 1e-5) << "layer " << k << " channel " << c;
      EXPECT_LT(s.standard_error, 0.01) << "too noisy to test anything";
    }
}

// The caches share the probe SH sums' buffer: a probe bake before (as `bake` runs them) leaves its
// sums there, which a per-bounce bake must overwrite whole, tables included, before it reads.
TEST(VulkanPerBounce, AProbeBakeBeforeLeavesNothingInTheCaches) {
  const float rho = 0.5f;
  const Vec3 one{1, 1, 1};
  const Vec3 emission[6] = {one, one, one, one, one, one};
  const testing::AtlasScene box = testing::atlas_box(rho, emission, 8);
  CREATE_VULKAN_OR_SKIP(vk, box.scene);
  std::vector<Vec3> probes(4096, Vec3{0.5f, 0.5f, 0.5f});  // SH sums of 884 KB, more than the caches need
  IntegratorSettings probe_settings;
  probe_settings.spp = 16;
  vk->bake_probes(probes, probe_settings);
  const LightmapEstimate e = vk->bake(box.gbuffer, bounce_settings(4, 1, 2));
  EXPECT_EQ(e.bounce_statistics.texelless_hits, 0u);
  // B_1 and B_2 = rho and rho^2: the furnace is exact per texel up to noise (4 samples: ~5 %).
  EXPECT_NEAR(mean_layer_over_texels(e, 1, 0), rho, 0.05 * rho);
  EXPECT_NEAR(mean_layer_over_texels(e, 2, 0), rho * rho, 0.05 * rho * rho);
}

// At rho 0.9 the tail criterion runs ~40 bounces and the completed tail restores Le / (1 - rho);
// a wrong gather (a lost albedo, a cache read from the wrong layer) moves the ratio and the total.
TEST(VulkanPerBounce, FurnaceWithTheTailCriterionReachesLeOverOneMinusAlbedo) {
  const float rho = 0.9f;
  const Vec3 one{1, 1, 1};
  const Vec3 emission[6] = {one, one, one, one, one, one};
  const testing::AtlasScene box = testing::atlas_box(rho, emission, 8);
  CREATE_VULKAN_OR_SKIP(vk, box.scene);
  std::vector<double> ratios;
  for (int seed = 0; seed < kSeeds; ++seed) {
    const LightmapEstimate e = vk->bake(box.gbuffer, bounce_settings(16, uint64_t(seed), -1));
    const BounceGatherStatistics& b = e.bounce_statistics;
    std::printf("[vulkan per-bounce] rho 0.9 seed %d: %d bounces, ratio %.4f, tail %.3g, noise %.3g\n", seed, b.bounces,
                b.ratio, b.tail_rms, b.noise_rms);
    EXPECT_TRUE(b.tail_below_noise);
    EXPECT_TRUE(b.tail_completed);
    EXPECT_NEAR(b.ratio, rho, 0.02);
    double total = 0;
    for (size_t i = 0; i < e.texels.size(); ++i) total += e.mean_total(i)[0];
    ratios.push_back(total / double(e.texels.size()) * (1 - rho));
  }
  const testing::MeanAndError s = testing::mean_and_standard_error(ratios);
  std::printf("[vulkan per-bounce] rho 0.9: estimate / closed form %.5f SE %.2g\n", s.mean, s.standard_error);
  EXPECT_LE(std::fabs(s.mean - 1), kZLimit * s.standard_error + 1e-5);
  EXPECT_LT(s.standard_error, 0.01);
}

// Under a time budget the last layer pass may run one more sample over a hashed part of the texels
// (the driver's work list holds just those): every texel's B_0 has m or m + 1 samples and equals, up
// to the order its device sums were added in, a --spp bake of its own count (B_0's random streams
// are per texel and sample; it reads no cache). Where the budget ended on a whole pass only m is seen.
// B_0 alone (--bounces 0), so the last pass is B_0's.
TEST(VulkanPerBounce, TimeBudgetTexelsHoldTheirOwnSampleMeans) {
  const Vec3 one{1, 1, 1};
  const Vec3 emission[6] = {one, one, one, one, one, one};
  const testing::AtlasScene box = testing::atlas_box(0.7f, emission, 8);
  CREATE_VULKAN_OR_SKIP(vk, box.scene);
  IntegratorSettings timed = bounce_settings(0, 9, 0);
  timed.time_budget_seconds = 0.5;
  const LightmapEstimate e = vk->bake(box.gbuffer, timed);
  const uint32_t m = e.bounce_statistics.samples.front();
  ASSERT_GE(m, 1u);
  std::printf("[vulkan per-bounce] 0.5 s budget: B_0 %u samples, %llu texels with one more\n", m,
              (unsigned long long)e.bounce_statistics.texels_with_one_more.front());
  for (uint32_t count : {m, m + 1}) {
    const LightmapEstimate fixed = vk->bake(box.gbuffer, bounce_settings(count, 9, 0));
    for (size_t i = 0; i < e.texels.size(); ++i) {
      ASSERT_TRUE(e.texels[i].samples == m || e.texels[i].samples == m + 1) << "texel " << i;
      if (e.texels[i].samples != count) continue;
      for (int c = 0; c < 3; ++c) {
        const float expected = fixed.mean_bounce(0, i)[c];
        ASSERT_NEAR(e.mean_bounce(0, i)[c], expected, 1e-5f * std::fabs(expected)) << "texel " << i;
      }
    }
  }
}

// A G-buffer without atlas rectangles: no gather hit has a texel to read, so every one goes on from
// the hit on the device (gather rays down to a direct-light sample): an unbiased path tracer split
// by bounce, whose per-texel errors are independent (no cache), against the furnace's closed form.
TEST(VulkanPerBounce, HitsWithoutTexelsAreEstimatedOnTheFly) {
  const testing::AnalyticScene a = testing::white_furnace(0.5f);
  CREATE_VULKAN_OR_SKIP(vk, a.scene);
  IntegratorSettings settings = bounce_settings(64, 11, 30);
  settings.trace_first_bounce = false;  // every layer tries its lookup (a traced B_1 never does)
  const LightmapEstimate e = vk->bake(a.gbuffer, settings);
  EXPECT_EQ(e.bounce_statistics.texelless_hits, e.bounce_statistics.gathers);
  EXPECT_GT(e.bounce_statistics.gathers, 0u);
  EXPECT_EQ(e.nonfinite_samples, 0u);
  std::vector<size_t> texels(a.gbuffer.texels.size());
  for (size_t i = 0; i < texels.size(); ++i) texels[i] = i;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> expected(a.exact);
    for (double& v : expected) v *= a.colour[c];
    const testing::GroupComparison g = testing::compare_group(e, texels, expected, c);
    std::printf("[vulkan per-bounce] no atlas, furnace 0.5 ch%d: exact %.5g estimate %.5g SE %.3g z %+.2f\n", c,
                g.expected, g.estimate, g.standard_error, g.z());
    EXPECT_LE(std::fabs(g.z()), kZLimit);
    EXPECT_LT(g.standard_error, 0.02 * g.expected);
  }
}

// B_0 alone (--bounces 0) reads no cache, so its texels are independent: the crosscheck's groups of
// 32 texels with the tracked variances of both backends (|z| < 4, lightmap_comparison.h).
TEST(VulkanPerBounce, CornellRoomDirectLayerAgreesWithTheCpuPerTexelGroup) {
  AtlasSettings atlas;
  atlas.texel_density = 4;
  Diagnostics diagnostics;
  const PreparedScene p = prepare_scene_for_lighting(EXITANCE_SAMPLE_DIR "/cornell_room.gltf", "", atlas, diagnostics);
  CREATE_VULKAN_OR_SKIP(vk, p.scene);
  const LightmapEstimate g = vk->bake(p.gbuffer, bounce_settings(256, 1, 0));
  const LightmapEstimate c = CpuReferenceIntegrator(p.scene).bake(p.gbuffer, bounce_settings(256, 2, 0));
  ASSERT_EQ(g.recorded_bounces, 1);
  testing::compare_estimates(g, c, 32, "per-bounce B_0 cornell_room");
  double signed_z = 0;  // reported: a shared offset would show here before any group fails
  size_t groups = 0;
  for (size_t begin = 0; begin < c.texels.size(); begin += 32, ++groups) {
    double a = 0, b = 0, v = 0;
    for (size_t i = begin; i < std::min(c.texels.size(), begin + 32); ++i)
      a += luminance(g.mean_total(i)), b += luminance(c.mean_total(i)),
          v += luminance(g.variance_of_mean(i)) + luminance(c.variance_of_mean(i));
    if (v > 0) signed_z += (a - b) / std::sqrt(v);
  }
  std::printf("[vulkan per-bounce] B_0 mean signed z over %zu groups %+.3f (expected 0 +- %.3f)\n", groups,
              signed_z / double(groups), 1 / std::sqrt(double(groups)));
}

// Each bounce layer of the Cornell room, per region (instance: walls, blocks, light), Vulkan
// against the CPU reference with the traced first bounce (the default) and with the cached one.
void cornell_layers_agree(bool trace_first_bounce) {
  AtlasSettings atlas;
  atlas.texel_density = 4;
  Diagnostics diagnostics;
  const PreparedScene p = prepare_scene_for_lighting(EXITANCE_SAMPLE_DIR "/cornell_room.gltf", "", atlas, diagnostics);
  CREATE_VULKAN_OR_SKIP(vk, p.scene);
  const CpuReferenceIntegrator cpu(p.scene);
  const int bounces = 3;
  // Per backend, region, layer: the luminance mean of each seed's run.
  using Means = std::map<uint32_t, std::vector<std::vector<double>>>;
  auto region_layer_means = [&](const LightmapEstimate& e, Means& out) {
    std::map<uint32_t, std::vector<double>> sum;
    std::map<uint32_t, double> count;
    for (size_t i = 0; i < e.texels.size(); ++i) {
      const uint32_t region = p.gbuffer.texels[i].instance;
      std::vector<double>& s = sum[region];
      s.resize(size_t(bounces) + 1, 0.0);
      for (int k = 0; k <= bounces; ++k) s[size_t(k)] += luminance(e.mean_bounce(k, i));
      count[region] += 1;
    }
    for (const auto& entry : sum) {
      std::vector<std::vector<double>>& layers = out[entry.first];
      layers.resize(size_t(bounces) + 1);
      for (int k = 0; k <= bounces; ++k) layers[size_t(k)].push_back(entry.second[size_t(k)] / count[entry.first]);
    }
  };
  Means gpu, reference;
  uint64_t gpu_texelless = 0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    IntegratorSettings s = bounce_settings(16, uint64_t(seed), bounces);
    s.trace_first_bounce = trace_first_bounce;
    const LightmapEstimate g = vk->bake(p.gbuffer, s);
    ASSERT_EQ(g.recorded_bounces, bounces + 1);
    EXPECT_EQ(g.nonfinite_samples, 0u);
    gpu_texelless += g.bounce_statistics.texelless_hits;
    region_layer_means(g, gpu);
    s.seed = 1000 + uint64_t(seed);
    region_layer_means(cpu.bake(p.gbuffer, s), reference);
  }
  ASSERT_GE(gpu.size(), 5u) << "walls, blocks and the light are regions";
  for (const auto& entry : gpu)
    for (int k = 0; k <= bounces; ++k) {
      const testing::MeanAndError g = testing::mean_and_standard_error(entry.second[size_t(k)]);
      const testing::MeanAndError c = testing::mean_and_standard_error(reference[entry.first][size_t(k)]);
      const double se = std::hypot(g.standard_error, c.standard_error);
      const double z = se > 0 ? (g.mean - c.mean) / se : 0.0;
      std::printf("[vulkan per-bounce] cornell %s region %u B_%d: vulkan %.5g cpu %.5g (%+.2f %%) z %+.2f\n",
                  trace_first_bounce ? "traced" : "cached", entry.first, k, g.mean, c.mean,
                  c.mean > 0 ? 100 * (g.mean - c.mean) / c.mean : 0.0, z);
      EXPECT_LE(std::fabs(g.mean - c.mean), kZLimit * se + 1e-6 * std::fabs(c.mean)) << "region " << entry.first << " B_" << k;
      // Resolution enough to see a few per cent (the light's own region has no bounce light from
      // its emitting face's back: skip regions that are black in a layer).
      if (c.mean > 1e-3) {
        EXPECT_LT(se, 0.03 * c.mean) << "region " << entry.first << " B_" << k << ": too noisy";
      }
    }
  std::printf("[vulkan per-bounce] cornell %s: %llu texelless gather hits on the device\n",
              trace_first_bounce ? "traced" : "cached", static_cast<unsigned long long>(gpu_texelless));
}

// The layer caches built on the device (bounce_cache.comp: clear, write, two dilation rings) are
// the host's BounceLayerCache pages (every word of every layer equal as a number, as each last
// build left it: the second ring, which no gather reaches here, included), so every gather reads
// the same values and the whole bake is the same bits as with the caches built on the host and uploaded. Cached first
// bounce too, where B_1 reads B_0's cache; a second bake in the same integrator reuses the buffers.
TEST(VulkanPerBounce, DeviceBuiltCachesEqualTheHostBuiltOnes) {
  AtlasSettings atlas;
  atlas.texel_density = 2;
  Diagnostics diagnostics;
  const PreparedScene p = prepare_scene_for_lighting(EXITANCE_SAMPLE_DIR "/cornell_room.gltf", "", atlas, diagnostics);
  CREATE_VULKAN_OR_SKIP(vk, p.scene);
  for (const bool traced : {false, true}) {
    SCOPED_TRACE(traced ? "traced first bounce" : "cached first bounce");
    IntegratorSettings s = bounce_settings(4, 5, 4);
    s.trace_first_bounce = traced;
    // Each layer's last build (layer -> its page words).
    std::map<size_t, std::vector<float>> device_pages, host_pages;
    s.inspect_bounce_cache = [&](size_t layer, const std::vector<float>& words) { device_pages[layer] = words; };
    const LightmapEstimate device = vk->bake(p.gbuffer, s);
    s.bounce_caches_on_host = true;
    s.inspect_bounce_cache = [&](size_t layer, const std::vector<float>& words) { host_pages[layer] = words; };
    const LightmapEstimate host = vk->bake(p.gbuffer, s);
    ASSERT_EQ(device_pages.size(), host_pages.size());
    ASSERT_GE(device_pages.size(), 3u) << "B_0 .. B_3 are read by gathers";
    for (const auto& [layer, words] : device_pages) {
      const std::vector<float>& expected = host_pages.at(layer);
      ASSERT_EQ(words.size(), expected.size());
      size_t unequal = 0, gutter = 0;
      // Equal as numbers: a dilated normal's 0 may come out -0 where the device's compiler drops an
      // add of +0 (measured: 6 words per layer), which no gather can tell apart.
      for (size_t w = 0; w < words.size(); ++w) unequal += !(words[w] == expected[w]);
      for (size_t t = 3; t < expected.size(); t += kBounceCacheTexelWords) gutter += expected[t] > 0;
      EXPECT_EQ(unequal, 0u) << "layer " << layer << ": page words differ";
      EXPECT_GT(gutter, 0u) << "layer " << layer << " has lit texels";
    }
    ASSERT_EQ(device.recorded_bounces, 5);
    ASSERT_EQ(device.texels.size(), host.texels.size());
    size_t differing = 0;
    for (size_t i = 0; i < device.texels.size(); ++i)
      differing += std::memcmp(&device.texels[i], &host.texels[i], sizeof(TexelAccumulator)) != 0;
    EXPECT_EQ(differing, 0u) << "texels whose sums differ";
    EXPECT_TRUE(device.bounces == host.bounces) << "bounce layers differ";
    EXPECT_GT(device.bounce_statistics.gathers, 0u);
  }
}

TEST(VulkanPerBounce, CornellRoomLayersAgreeWithTheCpuReference) { cornell_layers_agree(true); }
TEST(VulkanPerBounce, CornellRoomCachedFirstBounceAgreesWithTheCpuReference) { cornell_layers_agree(false); }

}  // namespace
}  // namespace exitance
