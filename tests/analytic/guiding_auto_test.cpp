// --guiding auto (issue 11) on the CPU backend: a pilot of guided and unguided samples on every texel,
// then each region keeps the strategy with the lower variance x counted cost (core/guiding_choice.h).
// Its candidate is grid guiding (AutoGuidingCandidate::Grid) or light subpaths (issue 35 item 4: the
// candidate wherever a light starts them); both are checked the same way.
// Mixing the two unbiased strategies in one texel's mean, with the choice made from earlier samples,
// is unbiased: auto converges to the unguided path tracer per region (Cornell room, ajar_room). The
// choice and the image are bit-identical per seed and thread count. In a white furnace cosine
// sampling is already ideal, so guiding cannot pay for its cost and every region drops it.
//
// Standard errors come from independent seeds (16 per estimator), as in guided_path_test.cpp:
// kZLimit = 5 (two-sided p ~ 1.3e-4 under Student's t with 15 dof per region; with up to ~25
// regions per test a false alarm stays below ~0.3 %), and each test checks it could see a 10 % bias.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>

#include "exitance/bake/command/bake_stages.h"
#include "exitance/bake/command/prepared_scene.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "support/atlas_box.h"
#include "support/identical_estimates.h"
#include "support/independent_estimates.h"
#include "support/prepared_sample.h"
#include "support/region_and_furnace_checks.h"

namespace exitance {
namespace {

constexpr double kZLimit = 5.0;
constexpr int kSeeds = 16;
constexpr double kDetectableBias = 0.10;

IntegratorSettings settings(uint32_t spp, uint64_t seed, GuidingMode guiding,
                            AutoGuidingCandidate candidate = AutoGuidingCandidate::Grid) {
  IntegratorSettings s;
  s.spp = spp;
  s.seed = seed;
  s.guiding = guiding;
  s.guiding_auto_candidate = candidate;
  return s;
}

// Auto against unguided, per region (instance), over kSeeds seeds each. Returns the median over
// regions of the relative standard error of the difference.
// `seeds_kept`: how many seeds kept the candidate in at least one region.
// `adaptive`: auto's samples planned per texel too (bake's default with --time), spp their mean.
double expect_auto_agrees(const std::string& label, const PreparedScene& p, uint32_t spp,
                          AutoGuidingCandidate candidate = AutoGuidingCandidate::Grid, int* seeds_kept = nullptr,
                          bool adaptive = false) {
  const CpuReferenceIntegrator integrator(p.scene);
  std::map<uint32_t, std::vector<double>> automatic, unguided;
  size_t decided = 0, regions_guided = 0, regions = 0;
  const bool light_subpaths = candidate == AutoGuidingCandidate::LightSubpaths;
  for (int seed = 0; seed < kSeeds; ++seed) {
    IntegratorSettings automatic_settings = settings(spp, uint64_t(seed), GuidingMode::Auto, candidate);
    automatic_settings.adaptive = adaptive;
    const LightmapEstimate a = integrator.bake(p.gbuffer, automatic_settings);
    EXPECT_EQ(a.adaptive, adaptive);
    if (adaptive && light_subpaths) {  // the plan follows the choice: after as many samples again where texels connect
      size_t connecting = 0;
      for (const RegionChoice& r : a.guiding_regions) connecting += r.texels_guided;
      EXPECT_EQ(a.adaptive_pilot, (connecting > 0 ? 2 : 1) * a.guiding_auto_pilot) << "seed " << seed;
    }
    const LightmapEstimate u = integrator.bake(p.gbuffer, settings(spp, uint64_t(seed) + 1000, GuidingMode::Off));
    EXPECT_EQ(a.nonfinite_samples, 0u);
    EXPECT_TRUE(a.guiding_auto);
    EXPECT_EQ(a.guiding_auto_light_subpaths, light_subpaths);
    if (light_subpaths)
      EXPECT_GT(a.light_subpaths, 0u);  // the pilot's connected samples' pools at least
    else
      EXPECT_GT(a.guided_vertices, 0u);  // the pilot's guided samples at least
    if (seeds_kept) *seeds_kept += a.guiding_regions.end() != std::find_if(a.guiding_regions.begin(), a.guiding_regions.end(),
                                                                            [](const RegionChoice& r) { return r.guided; });
    decided += !a.guiding_regions.empty();
    for (const RegionChoice& r : a.guiding_regions) regions_guided += r.guided, ++regions;
    for (auto& [region, m] : testing::region_means(p.gbuffer, testing::luminance_means(a))) automatic[region].push_back(m);
    for (auto& [region, m] : testing::region_means(p.gbuffer, testing::luminance_means(u))) unguided[region].push_back(m);
  }
  EXPECT_EQ(decided, size_t(kSeeds)) << label << ": the pilot must end within the bake";
  std::printf("[auto] %s: %zu of %zu guiding regions kept guiding over %d seeds\n", label.c_str(), regions_guided, regions,
              kSeeds);
  std::vector<double> relative_se;
  for (auto& [region, values] : unguided) {
    const testing::MeanAndError su = testing::mean_and_standard_error(values),
                                sa = testing::mean_and_standard_error(automatic[region]);
    const double se = std::hypot(su.standard_error, sa.standard_error);
    const double z = se > 0 ? (sa.mean - su.mean) / se : (sa.mean == su.mean ? 0.0 : INFINITY);
    std::printf("[auto] %s region %u: unguided %.5g auto %.5g (SE %.2g) z %+.2f\n", label.c_str(), region, su.mean,
                sa.mean, se, z);
    EXPECT_LE(std::fabs(z), kZLimit) << label << " region " << region;
    relative_se.push_back(su.mean > 0 ? se / su.mean : INFINITY);
  }
  std::sort(relative_se.begin(), relative_se.end());
  return relative_se[relative_se.size() / 2];
}

TEST(GuidingAuto, CornellRoomAgreesWithUnguided) {
  const PreparedScene p = testing::prepared_sample("cornell_room", 2);
  const double se = expect_auto_agrees("cornell_room", p, 64);
  EXPECT_LT(kZLimit * se, kDetectableBias) << "the test could not see a 10 % bias";
}

TEST(GuidingAuto, AjarRoomAgreesWithUnguided) {
  const PreparedScene p = testing::prepared_sample("ajar_room", 4);
  const double se = expect_auto_agrees("ajar_room", p, 64);
  EXPECT_LT(kZLimit * se, kDetectableBias) << "the test could not see a 10 % bias";
}

// Light subpaths as the candidate: the pilot's connected halves, then connections kept per region,
// the pilot's samples dropped where a texel connects, then adaptive sampling's pilot and plan (as
// bake --time runs it: its pilot follows the choice's, from samples 256 to 512, or is the choice's
// where no texel connects). At
// 1024 spp the pilot is its full 256 samples; at 2 texels/m ajar_room's few regions keep connections
// on some seeds only (7 of 16 when written), so both branches are checked against unguided.
TEST(GuidingAuto, LightPathCandidateOnAjarRoomAgreesWithUnguided) {
  const PreparedScene p = testing::prepared_sample("ajar_room", 2);
  int kept = 0;
  const double se = expect_auto_agrees("ajar_room light paths", p, 1024, AutoGuidingCandidate::LightSubpaths, &kept, true);
  EXPECT_LT(kZLimit * se, kDetectableBias) << "the test could not see a 10 % bias";
  std::printf("[auto] ajar_room light paths: %d of %d seeds kept connections somewhere\n", kept, kSeeds);
  EXPECT_GE(kept, 1) << "no seed kept connections: the branch after the choice went unchecked";
}

// The choice itself: at 4 texels/m ajar_room's evidence is clear (light through a door gap, where
// connections pay ~6x at equal time: bench/results/guiding-auto-light-paths.md; the scene's z read 6
// against the choice's threshold of 3), and the regions keep connections on the scene's evidence.
TEST(GuidingAuto, LightPathCandidateIsKeptOnAjarRoom) {
  const PreparedScene p = testing::prepared_sample("ajar_room", 4);
  const CpuReferenceIntegrator integrator(p.scene);
  for (uint64_t seed : {1, 2}) {
    const LightmapEstimate a = integrator.bake(p.gbuffer, settings(1024, seed, GuidingMode::Auto, AutoGuidingCandidate::LightSubpaths));
    ASSERT_FALSE(a.guiding_regions.empty());
    size_t kept = 0;
    for (const RegionChoice& r : a.guiding_regions) kept += r.guided;
    std::printf("[auto] ajar_room 4 texels/m seed %d: scene ratio %.2f z %.1f, %zu of %zu regions connect\n", int(seed),
                a.guiding_scene.efficiency_ratio(), a.guiding_scene.z(), kept, a.guiding_regions.size());
    EXPECT_GT(a.guiding_scene.z(), kChoiceZ) << "seed " << seed;
    EXPECT_GE(2 * kept, a.guiding_regions.size()) << "seed " << seed;
    EXPECT_GT(a.pilot_samples_dropped, 0u);
    // The probes follow the scene's verdict (bake_stages.h): every probe sample connects.
    BakeOptions options;
    options.lighting = settings(1024, seed, GuidingMode::Auto, AutoGuidingCandidate::LightSubpaths);
    const BakeOptions probes = probes_follow_texels(options, a);
    EXPECT_TRUE(probes.lighting.light_subpaths);
    EXPECT_EQ(probes.lighting.guiding, GuidingMode::Off);
    IntegratorSettings probe_settings = probes.lighting;
    probe_settings.spp = 256;
    EXPECT_GT(integrator.bake_probes({{0.0f, 1.5f, 0.0f}}, probe_settings).light_subpaths, 0u);
  }
}

// The Cornell room's ceiling light is seen by every surface: connections do not pay (the choice
// keeps them nowhere on significant evidence), and the pilot's connected samples stay unbiased.
TEST(GuidingAuto, LightPathCandidateOnCornellRoomAgreesWithUnguided) {
  const PreparedScene p = testing::prepared_sample("cornell_room", 2);
  const double se = expect_auto_agrees("cornell_room light paths", p, 64, AutoGuidingCandidate::LightSubpaths);
  EXPECT_LT(kZLimit * se, kDetectableBias) << "the test could not see a 10 % bias";
}

// The scene's candidate: light subpaths with an emissive triangle (the Cornell room's ceiling light)
// in a bake of four of their pilots (--spp 1024), grid guiding in a shorter one; and light subpaths
// under a sun alone (the courtyard: its subpaths start at infinity). Where connections do not pay
// (the Cornell room) the probes do not connect either.
TEST(GuidingAuto, SceneCandidateFollowsTheLights) {
  const PreparedScene cornell = testing::prepared_sample("cornell_room", 0.5);
  const CpuReferenceIntegrator cornell_integrator(cornell.scene);
  const LightmapEstimate c = cornell_integrator.bake(cornell.gbuffer, settings(1024, 1, GuidingMode::Auto, AutoGuidingCandidate::Scene));
  EXPECT_TRUE(c.guiding_auto_light_subpaths);
  EXPECT_GT(c.light_subpaths, 0u);
  BakeOptions options;
  options.lighting = settings(1024, 1, GuidingMode::Auto, AutoGuidingCandidate::Scene);
  EXPECT_FALSE(probes_follow_texels(options, c).lighting.light_subpaths) << "scene z " << c.guiding_scene.z();
  const LightmapEstimate short_bake =
      cornell_integrator.bake(cornell.gbuffer, settings(512, 1, GuidingMode::Auto, AutoGuidingCandidate::Scene));
  EXPECT_FALSE(short_bake.guiding_auto_light_subpaths);
  EXPECT_EQ(short_bake.light_subpaths, 0u);
  // The courtyard's only light is its sun: subpaths start there too (through the bounding sphere's disc).
  const PreparedScene courtyard = testing::prepared_sample("courtyard", 0.25);
  const CpuReferenceIntegrator courtyard_integrator(courtyard.scene);
  const LightmapEstimate y = courtyard_integrator.bake(courtyard.gbuffer, settings(1024, 1, GuidingMode::Auto, AutoGuidingCandidate::Scene));
  EXPECT_TRUE(y.guiding_auto_light_subpaths);
  EXPECT_GT(y.light_subpaths, 0u);
  EXPECT_GT(y.light_subpath_vertices, 0u);
  const LightmapEstimate grid =
      courtyard_integrator.bake(courtyard.gbuffer, settings(8, 1, GuidingMode::Auto, AutoGuidingCandidate::Scene));
  EXPECT_TRUE(grid.guiding_auto);
  EXPECT_FALSE(grid.guiding_auto_light_subpaths);
  EXPECT_EQ(grid.light_subpaths, 0u);
}

bool identical(const LightmapEstimate& a, const LightmapEstimate& b) {
  if (!testing::identical_texel_sums(a, b)) return false;
  if (a.guiding_regions.size() != b.guiding_regions.size()) return false;
  for (size_t r = 0; r < a.guiding_regions.size(); ++r)
    if (a.guiding_regions[r].guided != b.guiding_regions[r].guided ||
        a.guiding_regions[r].efficiency_ratio != b.guiding_regions[r].efficiency_ratio)
      return false;
  return true;
}

TEST(GuidingAuto, ChoiceAndResultBitIdenticalPerSeedAndThreadCount) {
  const PreparedScene p = testing::prepared_sample("ajar_room", 4);
  const CpuReferenceIntegrator integrator(p.scene);
  const LightmapEstimate a = integrator.bake(p.gbuffer, settings(96, 7, GuidingMode::Auto));
  ASSERT_FALSE(a.guiding_regions.empty()) << "96 spp: the pilot (16) ends within the bake";
  EXPECT_EQ(a.guiding_auto_pilot, 16u);
  const LightmapEstimate b = integrator.bake(p.gbuffer, settings(96, 7, GuidingMode::Auto));
  EXPECT_TRUE(identical(a, b)) << "two runs with one seed differ";
  {
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    const LightmapEstimate c = integrator.bake(p.gbuffer, settings(96, 7, GuidingMode::Auto));
    EXPECT_TRUE(identical(a, c)) << "one thread and all threads differ";
  }
  const LightmapEstimate other = integrator.bake(p.gbuffer, settings(96, 8, GuidingMode::Auto));
  EXPECT_FALSE(identical(a, other)) << "the seed must matter";
}

// The same with light subpaths as the candidate: pools sized by the connected share of each pass.
TEST(GuidingAuto, LightPathChoiceAndResultBitIdenticalPerSeedAndThreadCount) {
  const PreparedScene p = testing::prepared_sample("ajar_room", 2);
  const CpuReferenceIntegrator integrator(p.scene);
  const IntegratorSettings s = settings(96, 7, GuidingMode::Auto, AutoGuidingCandidate::LightSubpaths);
  const LightmapEstimate a = integrator.bake(p.gbuffer, s);
  ASSERT_FALSE(a.guiding_regions.empty()) << "96 spp: the pilot (16) ends within the bake";
  EXPECT_EQ(a.guiding_auto_pilot, 16u);
  EXPECT_GT(a.light_subpaths, 0u);
  EXPECT_TRUE(identical(a, integrator.bake(p.gbuffer, s))) << "two runs with one seed differ";
  {
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    EXPECT_TRUE(identical(a, integrator.bake(p.gbuffer, s))) << "one thread and all threads differ";
  }
  IntegratorSettings other = s;
  other.seed = 8;
  EXPECT_FALSE(identical(a, integrator.bake(p.gbuffer, other))) << "the seed must matter";
}

// A white furnace (every face emits Le, albedo rho): cosine sampling makes every bounce's
// contribution the same constant, so only Russian roulette is noise, and a guided mixture can only
// add weight variance and cost. The scene's measured efficiency ratio (unguided over guided) is
// below 1 by more than kZLimit standard errors over the seeds; regions keep cosine sampling (a region
// turns to guiding only on its own evidence beyond kChoiceZ: one-sided 1.3e-3 per region under a
// normal, at most 1 % of the regions allowed for heavier tails); the result meets Le / (1 - rho).
TEST(GuidingAuto, FurnaceDropsGuidingAndMeetsTheClosedForm) {
  const Vec3 le{1.0f, 0.5f, 0.25f};
  const float rho = 0.5f;
  const Vec3 emission[6] = {le, le, le, le, le, le};
  const testing::AtlasScene box = testing::atlas_box(rho, emission, 8);
  const CpuReferenceIntegrator integrator(box.scene);
  size_t measured = 0, guided = 0;
  std::vector<double> scene_ratios;
  testing::expect_furnace_closed_form("auto", le, rho, kSeeds, kZLimit, [&](uint64_t seed) {
    LightmapEstimate e = integrator.bake(box.gbuffer, settings(256, seed, GuidingMode::Auto));
    EXPECT_EQ(e.nonfinite_samples, 0u);
    EXPECT_EQ(e.guiding_auto_pilot, 64u);
    EXPECT_FALSE(e.guiding_regions.empty());
    scene_ratios.push_back(e.guiding_scene.efficiency_ratio());
    std::printf("[auto] furnace seed %d: scene efficiency ratio %.3f z %.1f\n", int(seed),
                e.guiding_scene.efficiency_ratio(), e.guiding_scene.z());
    for (const RegionChoice& r : e.guiding_regions) {
      if (r.texels_measured == 0) continue;
      ++measured;
      guided += r.guided;
    }
    return e;
  });
  EXPECT_GT(measured, 0u);
  EXPECT_LE(double(guided), 0.01 * double(measured)) << guided << " of " << measured << " regions kept guiding";
  const testing::MeanAndError ratio = testing::mean_and_standard_error(scene_ratios);
  std::printf("[auto] furnace: scene efficiency ratio %.3f +- %.3f\n", ratio.mean, ratio.standard_error);
  EXPECT_LT(ratio.mean + kZLimit * ratio.standard_error, 1.0);
}

}  // namespace
}  // namespace exitance
