// Light subpaths (bake --light-paths, common/light_subpaths.h, issue 35 item 3) on the CPU backend.
//  - Unbiased: with subpaths the estimate converges to the path tracer's per region (instance) and
//    per bounce layer (each path length is its own integral, so a wrong MIS weight for one strategy
//    shows in its layer), on a box lit by an emitter and a point light (with brighter lights outside
//    that reach nothing), the Cornell room, ajar_room and the building (point, spot and area lights),
//    a room lit through a door gap by a sun and a constant sky or an environment map (subpaths that
//    start at infinity); also with a bounce limit, and with emitter guiding (next-event estimation's learned
//    density then weighs the subpaths) against the unguided path tracer.
//  - Deterministic: bit-identical per seed and thread count.
//  - It pays where the path tracer is weak: ajar_room's variance at equal samples.
// Statistics as emitter_guided_path_test.cpp: kSeeds independent seeds, kZLimit = 5 standard errors,
// and each comparison checks its power (a 10 % bias in the median region must exceed kZLimit SE).
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "exitance/bake/command/prepared_scene.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "support/atlas_box.h"
#include "support/box_with_lights_outside.h"
#include "support/identical_estimates.h"
#include "support/independent_estimates.h"
#include "support/region_and_furnace_checks.h"
#include "support/region_runs.h"
#include "support/sky_lit_room.h"

namespace exitance {
namespace {

constexpr double kZLimit = 5.0;
constexpr int kSeeds = 16;
constexpr double kDetectableBias = 0.10;
constexpr int kLayers = 4;  // bounce0 .. bounce2 and the rest (IntegratorSettings::recorded_bounces)

// `per_sample`: light subpaths per texel sample; the agreement tests trace 1 (16x the default) so
// that the strategies with light vertices carry more of each estimate: the test's power is theirs.
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

// With subpaths against without, per region and bounce layer, over kSeeds seeds each; returns the
// median over regions of the relative standard error of the totals' difference.
double expect_regions_agree(const std::string& label, const Scene& scene, const TexelGBuffer& gbuffer, uint32_t spp,
                            int max_bounces = -1, bool emitter_guiding = false) {
  const CpuReferenceIntegrator integrator(scene);
  testing::RegionRuns with, without, layers_with[kLayers], layers_without[kLayers];
  uint64_t subpaths = 0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    IntegratorSettings a = settings(spp, uint64_t(seed), true, 1.0, emitter_guiding), b = settings(spp, uint64_t(seed) + 1000, false);
    a.max_bounces = b.max_bounces = max_bounces;
    const LightmapEstimate w = integrator.bake(gbuffer, a);
    const LightmapEstimate u = integrator.bake(gbuffer, b);
    EXPECT_EQ(w.nonfinite_samples, 0u);
    EXPECT_EQ(u.nonfinite_samples, 0u);
    subpaths += w.light_subpaths;
    testing::add_regions(gbuffer, w, with);
    testing::add_regions(gbuffer, u, without);
    for (int k = 0; k < kLayers; ++k) {
      testing::add_layer_regions(gbuffer, w, k, layers_with[k]);
      testing::add_layer_regions(gbuffer, u, k, layers_without[k]);
    }
  }
  EXPECT_GT(subpaths, 0u) << "no light subpath was traced";
  for (int k = 0; k < kLayers; ++k) {
    // Layers without light (direct light where none reaches) have nothing to compare.
    testing::RegionRuns lit_with, lit_without;
    for (const auto& [region, runs] : layers_without[k])
      if (testing::mean_and_standard_error(runs).mean > 0 || testing::mean_and_standard_error(layers_with[k].at(region)).mean > 0)
        lit_with[region] = layers_with[k].at(region), lit_without[region] = runs;
    if (!lit_without.empty())
      testing::expect_regions_agree("light subpaths", label + " bounce" + std::to_string(k), lit_without, lit_with, kZLimit);
  }
  return testing::expect_regions_agree("light subpaths", label, without, with, kZLimit);
}

PreparedScene sample_scene(const char* name, float density) {
  AtlasSettings atlas;
  atlas.texel_density = density;
  Diagnostics diagnostics;
  return prepare_scene_for_lighting(std::string(EXITANCE_SAMPLE_DIR "/") + name + ".gltf", "", atlas, diagnostics);
}

// A sample scene agrees, and the comparison could see a 10 % bias.
void expect_sample_scene_agrees(const char* name, float density, uint32_t spp, bool emitter_guiding = false) {
  const PreparedScene p = sample_scene(name, density);
  const std::string label = std::string(name) + (emitter_guiding ? ", emitter guided" : "");
  EXPECT_LT(kZLimit * expect_regions_agree(label, p.scene, p.gbuffer, spp, -1, emitter_guiding), kDetectableBias)
      << "the test could not see a 10 % bias";
}

TEST(LightSubpaths, BoxWithLightsOutsideAgreesWithPathTracing) {
  const testing::AtlasScene box = testing::box_with_lights_outside_and_a_spot();
  EXPECT_LT(kZLimit * expect_regions_agree("box", box.scene, box.gbuffer, 64), kDetectableBias)
      << "the test could not see a 10 % bias";
}

TEST(LightSubpaths, BoxAgreesUnderABounceLimit) {
  const testing::AtlasScene box = testing::box_with_lights_outside_and_a_spot();
  EXPECT_LT(kZLimit * expect_regions_agree("box, 2 bounces", box.scene, box.gbuffer, 64, 2), kDetectableBias)
      << "the test could not see a 10 % bias";
}

// Emitter guiding learns that the lights outside never arrive: next-event estimation's density
// then differs from the subpaths' start density by up to 100x, which the weights must follow.
TEST(LightSubpaths, BoxWithEmitterGuidingAgreesWithPathTracing) {
  const testing::AtlasScene box = testing::box_with_lights_outside_and_a_spot();
  EXPECT_LT(kZLimit * expect_regions_agree("box, emitter guided", box.scene, box.gbuffer, 64, -1, true), kDetectableBias)
      << "the test could not see a 10 % bias";
}

// Subpaths from the sky and a sun (starts at infinity, through the bounding sphere's disc) into a
// room they light only through a door gap: a constant sky (no next-event strategy: the eye's escape
// stands in for it) and an environment map (importance sampled by NEE and the subpaths alike).
TEST(LightSubpaths, SkyLitRoomAgreesWithPathTracing) {
  const testing::AtlasScene room = testing::sky_lit_room(false, 6);
  EXPECT_LT(kZLimit * expect_regions_agree("sky-lit room", room.scene, room.gbuffer, 256), kDetectableBias)
      << "the test could not see a 10 % bias";
}

TEST(LightSubpaths, EnvironmentLitRoomAgreesWithPathTracing) {
  const testing::AtlasScene room = testing::sky_lit_room(true, 6);
  EXPECT_LT(kZLimit * expect_regions_agree("environment-lit room", room.scene, room.gbuffer, 256), kDetectableBias)
      << "the test could not see a 10 % bias";
}

TEST(LightSubpaths, AjarRoomWithEmitterGuidingAgreesWithPathTracing) { expect_sample_scene_agrees("ajar_room", 4, 64, true); }

TEST(LightSubpaths, CornellRoomAgreesWithPathTracing) { expect_sample_scene_agrees("cornell_room", 2, 32); }

TEST(LightSubpaths, AjarRoomAgreesWithPathTracing) { expect_sample_scene_agrees("ajar_room", 4, 64); }

TEST(LightSubpaths, BuildingAgreesWithPathTracing) { expect_sample_scene_agrees("building", 0.5f, 64); }

// Probes (bake --light-paths on connects their paths too, from each probe ray's first hit): the
// SH's constant term per probe and channel against the path tracer's, over kSeeds seeds, in the box
// with a spot light and far brighter lights outside; bit-identical per seed and thread count.
TEST(LightSubpaths, ProbesAgreeWithPathTracing) {
  const testing::AtlasScene box = testing::box_with_lights_outside_and_a_spot();
  const CpuReferenceIntegrator integrator(box.scene);
  const std::vector<Vec3> probes = {{0.5f, 0.5f, 0.5f}, {0.25f, 0.2f, 0.25f}, {0.75f, 0.3f, 0.6f}, {0.3f, 0.75f, 0.7f}};
  testing::RegionRuns with, without;
  uint64_t subpaths = 0;
  auto add = [&](const ProbeEstimate& e, testing::RegionRuns& runs) {
    EXPECT_EQ(e.nonfinite_samples, 0u);
    for (size_t i = 0; i < probes.size(); ++i)
      for (int c = 0; c < 3; ++c) runs[uint32_t(i * 3 + size_t(c))].push_back(e.sh_sum[i][size_t(c)] / double(e.samples[i]));
  };
  for (int seed = 0; seed < kSeeds; ++seed) {
    const ProbeEstimate w = integrator.bake_probes(probes, settings(4096, uint64_t(seed), true));
    subpaths += w.light_subpaths;
    add(w, with);
    add(integrator.bake_probes(probes, settings(4096, uint64_t(seed) + 1000, false)), without);
  }
  EXPECT_GT(subpaths, 0u) << "no light subpath was traced for the probes";
  EXPECT_LT(kZLimit * testing::expect_regions_agree("light subpaths", "box probes", without, with, kZLimit), kDetectableBias)
      << "the test could not see a 10 % bias";
  const ProbeEstimate a = integrator.bake_probes(probes, settings(256, 7, true, 0.25));
  const ProbeEstimate b = integrator.bake_probes(probes, settings(256, 7, true, 0.25));
  tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  const ProbeEstimate c = integrator.bake_probes(probes, settings(256, 7, true, 0.25));
  EXPECT_TRUE(a.sh_sum == b.sh_sum && a.sh_sum == c.sh_sum) << "runs with one seed differ";
  EXPECT_FALSE(a.sh_sum == integrator.bake_probes(probes, settings(256, 7, false)).sh_sum) << "subpaths must change the samples";
}

TEST(LightSubpaths, BitIdenticalPerSeedAndThreadCount) {
  const testing::AtlasScene box = testing::box_with_lights_outside();
  const CpuReferenceIntegrator integrator(box.scene);
  const LightmapEstimate a = integrator.bake(box.gbuffer, settings(24, 7, true, 0.25));
  const LightmapEstimate b = integrator.bake(box.gbuffer, settings(24, 7, true, 0.25));
  EXPECT_TRUE(testing::identical_texel_sums(a, b)) << "two runs with one seed differ";
  {
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    const LightmapEstimate c = integrator.bake(box.gbuffer, settings(24, 7, true, 0.25));
    EXPECT_TRUE(testing::identical_texel_sums(a, c)) << "one thread and all threads differ";
  }
  const LightmapEstimate without = integrator.bake(box.gbuffer, settings(24, 7, false));
  EXPECT_FALSE(testing::identical_texel_sums(a, without)) << "light subpaths must change the samples";
}

TEST(LightSubpaths, LowerAjarRoomsVarianceAtEqualSamples) {
  const PreparedScene p = sample_scene("ajar_room", 4);
  const CpuReferenceIntegrator integrator(p.scene);
  std::vector<std::vector<double>> with, without;
  for (int seed = 0; seed < 8; ++seed) {
    with.push_back(testing::luminance_means(integrator.bake(p.gbuffer, settings(16, uint64_t(seed), true, 0.25))));
    without.push_back(testing::luminance_means(integrator.bake(p.gbuffer, settings(16, uint64_t(seed) + 1000, false))));
  }
  const double ratio = testing::mean_relative_variance(with) / testing::mean_relative_variance(without);
  std::printf("[light subpaths] ajar_room relative variance per texel at 16 spp: with / without = %.3f\n", ratio);
  EXPECT_LT(ratio, 0.5);
}

// The sky's and the sun's subpaths pay less than a lamp's beside the gap (their disc is the whole
// scene's, so few pass the gap), but at equal samples they still lower the door-gap room's variance.
TEST(LightSubpaths, LowerSkyLitRoomsVarianceAtEqualSamples) {
  for (const bool environment : {false, true}) {
    const testing::AtlasScene room = testing::sky_lit_room(environment, 16);
    const CpuReferenceIntegrator integrator(room.scene);
    std::vector<std::vector<double>> with, without;
    uint64_t rays_with = 0, rays_without = 0;
    for (int seed = 0; seed < 8; ++seed) {
      const LightmapEstimate a = integrator.bake(room.gbuffer, settings(16, uint64_t(seed), true, 0.25));
      const LightmapEstimate b = integrator.bake(room.gbuffer, settings(16, uint64_t(seed) + 1000, false));
      rays_with += a.rays, rays_without += b.rays;
      with.push_back(testing::luminance_means(a));
      without.push_back(testing::luminance_means(b));
    }
    const double ratio = testing::mean_relative_variance(with) / testing::mean_relative_variance(without);
    std::printf("[light subpaths] %s room relative variance per texel at 16 spp: with / without = %.3f for %.2fx the rays\n",
                environment ? "environment-lit" : "sky-lit", ratio, double(rays_with) / double(rays_without));
    EXPECT_LT(ratio, 0.85);
  }
}

}  // namespace
}  // namespace exitance
