// --guiding auto (issue 11) on the CPU backend: a pilot of guided and unguided samples on every texel,
// then each region keeps the strategy with the lower variance x counted cost (core/guiding_choice.h).
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

IntegratorSettings settings(uint32_t spp, uint64_t seed, GuidingMode guiding) {
  IntegratorSettings s;
  s.spp = spp;
  s.seed = seed;
  s.guiding = guiding;
  return s;
}

// Auto against unguided, per region (instance), over kSeeds seeds each. Returns the median over
// regions of the relative standard error of the difference.
double expect_auto_agrees(const std::string& label, const PreparedScene& p, uint32_t spp) {
  const CpuReferenceIntegrator integrator(p.scene);
  std::map<uint32_t, std::vector<double>> automatic, unguided;
  size_t decided = 0, regions_guided = 0, regions = 0;
  for (int seed = 0; seed < kSeeds; ++seed) {
    const LightmapEstimate a = integrator.bake(p.gbuffer, settings(spp, uint64_t(seed), GuidingMode::Auto));
    const LightmapEstimate u = integrator.bake(p.gbuffer, settings(spp, uint64_t(seed) + 1000, GuidingMode::Off));
    EXPECT_EQ(a.nonfinite_samples, 0u);
    EXPECT_TRUE(a.guiding_auto);
    EXPECT_GT(a.guided_vertices, 0u);  // the pilot's guided samples at least
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
