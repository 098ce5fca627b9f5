// Light subpaths (bake --light-paths on, issue 35 item 3) on the Vulkan backend: each batch's pool
// traced on the device (shaders/wavefront/light_subpaths.comp, the CPU pool's walk in
// common/light_subpath_walk.h) and every eye vertex connected to one pool vertex through the
// wavefront's last shadow slot, weighted by the CPU's MIS (path.h). Checked against the CPU
// reference's path tracer, per region and per bounce layer (each path length is its own integral,
// so a wrong weight for one strategy shows in its layer), over kSeeds seeds: a box lit by an
// emitter, a point and a spot light (brighter lights outside reach nothing), and a room lit through
// a door gap by a sun and a constant sky (subpaths that start at infinity; the eye's escape stands
// in for NEE) or an environment map; the box with emitter guiding beside them; the box's probes too. The same seed gives the same bits, and
// ajar_room's variance falls as on the CPU. Validation layers on; without a Vulkan device, SKIP.
// Statistics as light_subpaths_test.cpp: kZLimit = 5 standard errors per region, each comparison's
// power checked (a 10 % bias in the median region must exceed kZLimit SEs).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "exitance/bake/command/prepared_scene.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "support/box_with_lights_outside.h"
#include "support/identical_estimates.h"
#include "support/independent_estimates.h"
#include "support/prepared_sample.h"
#include "support/region_and_furnace_checks.h"
#include "support/region_runs.h"
#include "support/sky_lit_room.h"
#include "support/validated_vulkan_backend.h"

namespace exitance {
namespace {

constexpr double kZLimit = 5.0;
constexpr int kSeeds = 16;
constexpr double kDetectableBias = 0.10;
constexpr int kLayers = 4;  // bounce0 .. bounce2 and the rest

// `per_sample` 1 in the agreement tests (16x the default), so that the strategies with light
// vertices carry more of each estimate: the test's power is theirs.
IntegratorSettings settings(uint32_t spp, uint64_t seed, bool subpaths, double per_sample = 1.0, bool emitter_guiding = false) {
  IntegratorSettings s;
  s.emitter_guiding = emitter_guiding;
  s.spp = spp;
  s.seed = seed;
  s.light_subpaths = subpaths;
  s.light_subpaths_per_sample = per_sample;
  s.recorded_bounces = kLayers;
  return s;
}

// One seed's device estimate with subpaths (default: a bake).
using DeviceRun = std::function<LightmapEstimate(VulkanIntegrator&, const IntegratorSettings&)>;

// The device with subpaths against the CPU's path tracer, per region and bounce layer.
void expect_device_agrees(const std::string& label, const Scene& scene, const TexelGBuffer& gbuffer, uint32_t spp,
                          const DeviceRun& device = nullptr, bool emitter_guiding = false) {
  CREATE_VULKAN_OR_SKIP(vk, scene);
  const CpuReferenceIntegrator cpu(scene);
  testing::RegionRuns with, without, layers_with[kLayers], layers_without[kLayers];
  uint64_t subpaths = 0, vertices = 0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    const IntegratorSettings s = settings(spp, uint64_t(seed), true, 1.0, emitter_guiding);
    const LightmapEstimate w = device ? device(*vk.operator->(), s) : vk->bake(gbuffer, s);
    if (emitter_guiding) EXPECT_GT(w.emitter_guiding.records_sampling_learned, 0u) << "no record samples what it learned";
    const LightmapEstimate u = cpu.bake(gbuffer, settings(spp, uint64_t(seed) + 1000, false));
    EXPECT_EQ(w.nonfinite_samples, 0u);
    subpaths += w.light_subpaths, vertices += w.light_subpath_vertices;
    testing::add_regions(gbuffer, w, with);
    testing::add_regions(gbuffer, u, without);
    for (int k = 0; k < kLayers; ++k) {
      testing::add_layer_regions(gbuffer, w, k, layers_with[k]);
      testing::add_layer_regions(gbuffer, u, k, layers_without[k]);
    }
  }
  std::printf("[vulkan light subpaths] %s: %llu subpaths, %llu vertices over %d seeds\n", label.c_str(),
              (unsigned long long)subpaths, (unsigned long long)vertices, kSeeds);
  EXPECT_GT(vertices, 0u) << "no light-subpath vertex was kept";
  for (int k = 0; k < kLayers; ++k) {
    testing::RegionRuns lit_with, lit_without;  // layers where light arrives
    for (const auto& [region, runs] : layers_without[k])
      if (testing::mean_and_standard_error(runs).mean > 0 || testing::mean_and_standard_error(layers_with[k].at(region)).mean > 0)
        lit_with[region] = layers_with[k].at(region), lit_without[region] = runs;
    if (!lit_without.empty())
      testing::expect_regions_agree("vulkan light subpaths", label + " bounce" + std::to_string(k), lit_without, lit_with, kZLimit);
  }
  const double se = testing::expect_regions_agree("vulkan light subpaths", label, without, with, kZLimit);
  EXPECT_LT(kZLimit * se, kDetectableBias) << "the test could not see a 10 % bias";
}

TEST(VulkanLightSubpaths, BoxAgreesWithCpuPathTracing) {
  const testing::AtlasScene box = testing::box_with_lights_outside_and_a_spot();
  expect_device_agrees("box", box.scene, box.gbuffer, 256);
}

// Emitter guiding beside them (learned on the device, folded between passes): it learns that the
// lights outside never arrive, so next-event estimation's density differs from the subpaths' start
// density by up to 100x; the pools' first hits and the eye's weights must both follow it.
TEST(VulkanLightSubpaths, BoxWithEmitterGuidingAgreesWithCpuPathTracing) {
  const testing::AtlasScene box = testing::box_with_lights_outside_and_a_spot();
  expect_device_agrees("box, emitter guided", box.scene, box.gbuffer, 128, nullptr, true);
}

TEST(VulkanLightSubpaths, SkyLitRoomAgreesWithCpuPathTracing) {
  const testing::AtlasScene room = testing::sky_lit_room(false, 6);
  expect_device_agrees("sky-lit room", room.scene, room.gbuffer, 256);
}

// An environment map instead (importance sampled by NEE and the subpaths alike; the connection in a
// fourth shadow slot beside the environment's).
TEST(VulkanLightSubpaths, EnvironmentLitRoomAgreesWithCpuPathTracing) {
  const testing::AtlasScene room = testing::sky_lit_room(true, 6);
  expect_device_agrees("environment-lit room", room.scene, room.gbuffer, 256);
}

// The progressive accumulation (the runtime's refresh, RefreshSessionOptions::light_subpaths) connects
// too: 256 samples added in uneven calls (1, 3, 60, 192), each pass's batches with their own pool,
// agree with the CPU's path tracer per region and bounce layer. With light layers on, each
// connection lands in the layer of the light its subpath started from, so the layers still add up
// to each texel's estimate (within float rounding: the device sums in floats).
TEST(VulkanLightSubpaths, ProgressiveAccumulationAgreesWithCpuPathTracing) {
  const testing::AtlasScene box = testing::box_with_lights_outside_and_a_spot();
  expect_device_agrees("box, progressive", box.scene, box.gbuffer, 256, [&](VulkanIntegrator& vk, const IntegratorSettings& s) {
    IntegratorSettings layered = s;
    layered.light_layers = true;
    vk.start_progressive(box.gbuffer, layered);
    for (const uint32_t samples : {1u, 3u, 60u, 192u}) vk.add_samples(samples);
    LightmapEstimate e = vk.progressive_estimate();
    EXPECT_GT(e.light_layers, 1);
    const size_t n = e.texels.size();
    double largest_gap = 0;
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        double layers = 0;
        for (int k = 0; k < e.light_layers; ++k) layers += e.light_sums[(size_t(k) * n + i) * 3 + size_t(c)];
        largest_gap = std::max(largest_gap, std::abs(layers - e.texels[i].total[c]) / std::max(1e-3, std::abs(e.texels[i].total[c])));
      }
    EXPECT_LT(largest_gap, 1e-4) << "the light layers do not add up to the texels' estimates";
    return e;
  });
}

// Probes connect too, from each probe ray's first hit (the path's fixed x_0): the SH's constant term
// per probe and channel against the CPU path tracer's probes over kSeeds seeds, in the box with a spot
// light and far brighter lights outside, baked and refreshed (the runtime's probe sets, one
// stratified set per call); the same seed gives the same sums.
TEST(VulkanLightSubpaths, ProbesAgreeWithCpuPathTracing) {
  const testing::AtlasScene box = testing::box_with_lights_outside_and_a_spot();
  CREATE_VULKAN_OR_SKIP(vk, box.scene);
  const CpuReferenceIntegrator cpu(box.scene);
  const std::vector<Vec3> probes = {{0.5f, 0.5f, 0.5f}, {0.25f, 0.2f, 0.25f}, {0.75f, 0.3f, 0.6f}, {0.3f, 0.75f, 0.7f}};
  testing::RegionRuns with, refreshed, without;
  uint64_t subpaths = 0, refreshed_subpaths = 0;
  auto add = [&](const ProbeEstimate& e, testing::RegionRuns& runs) {
    EXPECT_EQ(e.nonfinite_samples, 0u);
    for (size_t i = 0; i < probes.size(); ++i)
      for (int c = 0; c < 3; ++c) runs[uint32_t(i * 3 + size_t(c))].push_back(e.sh_sum[i][size_t(c)] / double(e.samples[i]));
  };
  for (int seed = 0; seed < kSeeds; ++seed) {
    const ProbeEstimate w = vk->bake_probes(probes, settings(4096, uint64_t(seed), true));
    subpaths += w.light_subpaths;
    add(w, with);
    add(cpu.bake_probes(probes, settings(4096, uint64_t(seed) + 1000, false)), without);
    vk->start_probe_refresh(probes);
    while (vk->refresh_probe_set(settings(4096, uint64_t(seed) + 2000, true), 4096) > 0) {
    }
    const ProbeEstimate r = vk->probe_refresh_estimate();
    refreshed_subpaths += r.light_subpaths;
    add(r, refreshed);
  }
  EXPECT_GT(subpaths, 0u) << "no light subpath was traced for the probes";
  EXPECT_GT(refreshed_subpaths, 0u) << "no light subpath was traced for the refreshed probes";
  EXPECT_LT(kZLimit * testing::expect_regions_agree("vulkan light subpaths", "box probes", without, with, kZLimit), kDetectableBias)
      << "the test could not see a 10 % bias";
  EXPECT_LT(kZLimit * testing::expect_regions_agree("vulkan light subpaths", "box probes refreshed", without, refreshed, kZLimit),
            kDetectableBias)
      << "the test could not see a 10 % bias";
  // (Most subpaths start at the far brighter lights outside and leave no vertex: a whole subpath per
  // sample keeps some in a 256-sample pool.)
  const ProbeEstimate a = vk->bake_probes(probes, settings(256, 7, true));
  const ProbeEstimate b = vk->bake_probes(probes, settings(256, 7, true));
  EXPECT_GT(a.light_subpaths, 0u);
  EXPECT_TRUE(a.sh_sum == b.sh_sum) << "runs with one seed differ";
  EXPECT_FALSE(a.sh_sum == vk->bake_probes(probes, settings(256, 7, false)).sh_sum) << "subpaths must change the samples";
}

// One seed, the same bits (the pool is written in subpath order); subpaths change the samples; and
// where the path tracer is weak (ajar_room's lamp behind a 5 cm gap) the texels' variance at equal
// samples falls as on the CPU (light_subpaths_test.cpp: below half).
TEST(VulkanLightSubpaths, BitIdenticalPerSeedAndLowerAjarRoomsVariance) {
  const PreparedScene p = testing::prepared_sample("ajar_room", 4);
  CREATE_VULKAN_OR_SKIP(vk, p.scene);
  const LightmapEstimate a = vk->bake(p.gbuffer, settings(16, 7, true, 0.25));
  const LightmapEstimate b = vk->bake(p.gbuffer, settings(16, 7, true, 0.25));
  EXPECT_TRUE(testing::identical_texel_sums(a, b)) << "two runs with one seed differ";
  EXPECT_GT(a.light_subpath_vertices, 0u);
  std::vector<std::vector<double>> with, without;
  for (int seed = 0; seed < kSeeds; ++seed) {
    with.push_back(testing::luminance_means(vk->bake(p.gbuffer, settings(16, uint64_t(seed), true, 0.25))));
    without.push_back(testing::luminance_means(vk->bake(p.gbuffer, settings(16, uint64_t(seed) + 1000, false))));
  }
  EXPECT_FALSE(with[7] == without[7]);
  const double ratio = testing::mean_relative_variance(with) / testing::mean_relative_variance(without);
  std::printf("[vulkan light subpaths] ajar_room relative variance per texel at 16 spp: with / without = %.3f\n", ratio);
  EXPECT_LT(ratio, 0.5);
}

// What light subpaths are not combined with on this backend is refused, not ignored.
TEST(VulkanLightSubpaths, RefusedWhereNotCombined) {
  const testing::AtlasScene box = testing::box_with_lights_outside();
  CREATE_VULKAN_OR_SKIP(vk, box.scene);
  IntegratorSettings s = settings(4, 1, true);
  s.guiding = GuidingMode::Grid;
  EXPECT_THROW(vk->bake(box.gbuffer, s), std::invalid_argument);
  s = settings(4, 1, true);
  s.integrator = IntegratorMode::Bounces;
  EXPECT_THROW(vk->bake(box.gbuffer, s), std::invalid_argument);
}

}  // namespace
}  // namespace exitance
