// Emitter guiding (bake --emitter-guiding on, issue 11) on the CPU backend.
//  - The shared math (guided_emitters.h): sub-triangles partition a triangle into equal areas and are
//    found again from their points; patches follow the power shares; the mixture samples exactly the
//    density it reports (chi-square over emitters x sub-triangles and over punctual lights), and that
//    density integrates to 1.
//  - The cache learns: in a closed box lit by a small lamp and a point light inside, with a far brighter
//    emitter and point light outside, every record's learned distributions put most of their mass on
//    the lights inside (the default sampling by power gives them < 1 %).
//  - Forced on, the guided estimator converges to the unguided one per region (instance) on that box,
//    the Cornell room, ajar_room and the building (many emitters, point and spot lights), and the
//    per-bounce mode's guided direct layers to its unguided ones; no NaN/Inf; bit-identical per seed
//    and thread count.
// Statistics as svo_guided_path_test.cpp: kSeeds independent seeds, kZLimit = 5 standard errors, and
// each comparison checks its power (a 10 % bias in the median region must exceed kZLimit SE).
// Chi-square limits: the Wilson-Hilferty quantile at z = 4.75 (upper tail ~1e-6).
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "exitance/bake/command/prepared_scene.h"
#include "exitance/runtime/core/emitter_guiding_cache.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "support/atlas_box.h"
#include "support/box_with_lights_outside.h"
#include "support/identical_estimates.h"
#include "support/independent_estimates.h"
#include "support/region_and_furnace_checks.h"
#include "support/region_runs.h"

namespace exitance {
namespace {

constexpr double kZLimit = 5.0;
constexpr int kSeeds = 16;
constexpr double kDetectableBias = 0.10;

double chi_square_limit(double dof) {
  const double z = 4.75, a = 2.0 / (9.0 * dof);
  return dof * std::pow(1.0 - a + z * std::sqrt(a), 3.0);
}

// Sum of (observed - expected)^2 / expected over cells with expected > 0; observed where expected is 0
// fails on its own.
double chi_square(const std::vector<double>& observed, const std::vector<double>& expected, double& dof) {
  double chi = 0;
  dof = -1;
  for (size_t k = 0; k < observed.size(); ++k) {
    if (expected[k] > 0) {
      chi += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
      dof += 1;
    } else {
      EXPECT_EQ(observed[k], 0.0) << "a cell of probability 0 was sampled: " << k;
    }
  }
  return chi;
}

std::vector<double> cdf_of(const std::vector<double>& shares) {
  std::vector<double> cdf{0.0};
  for (double s : shares) cdf.push_back(cdf.back() + s);
  for (double& c : cdf) c /= cdf.back();
  return cdf;
}

TEST(EmitterPatches, SubTrianglesAreEqualAreasFoundFromTheirPoints) {
  std::mt19937 random(11);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (uint level = 0; level <= kEmitterPatchMaxLevel; ++level) {
    const uint subs = 1u << (2 * level);
    std::vector<double> observed(subs, 0.0), expected(subs, 64.0);
    for (uint n = 0; n < subs * 64; ++n) {
      const vec2 b = sample_triangle_barycentrics(unit(random), unit(random));
      observed[emitter_sub_triangle_of(level, b.x, b.y)] += 1;
    }
    double dof = 0;
    if (subs > 1) {
      const double chi = chi_square(observed, expected, dof);
      EXPECT_LT(chi, chi_square_limit(dof)) << "level " << level;
    }
    for (int n = 0; n < 2000; ++n) {
      const uint index = uint(random() % subs);
      // A point well inside the sub-triangle (1 % of its size from every edge).
      const vec2 c = sample_triangle_barycentrics(0.01f + 0.98f * unit(random), 0.01f + 0.98f * unit(random));
      const float c1 = 0.01f + 0.97f * c.x, c2 = 0.01f + 0.97f * c.y;
      const vec2 b = emitter_sub_triangle_point(level, index, c1, c2);
      ASSERT_EQ(emitter_sub_triangle_of(level, b.x, b.y), index) << "level " << level;
    }
  }
}

TEST(EmitterPatches, FollowThePowerShares) {
  const std::vector<double> cdf = cdf_of({0.5, 0.3, 0.1, 0.04, 0.03, 0.02, 0.01});
  const EmitterPatches p = build_emitter_patches(cdf, 16, 4);
  // 0.5 x 16 = 8: 4 sub-triangles; 0.3 x 16 = 4.8: 4; 0.1 x 16 = 1.6: its own patch; then runs of at
  // most 1/16: {0.04}, {0.03, 0.02, 0.01}.
  ASSERT_EQ(p.count(), 11u);
  EXPECT_EQ(p.emitter_patch[0], 0u << 3 | 1u);
  EXPECT_EQ(p.emitter_patch[1], 4u << 3 | 1u);
  EXPECT_EQ(p.emitter_patch[2], 8u << 3);
  EXPECT_EQ(p.emitter_patch[3], 9u << 3);
  for (int e = 4; e < 7; ++e) EXPECT_EQ(p.emitter_patch[size_t(e)], 10u << 3);
  EXPECT_EQ(p.patch_emitters[2 * 10], 4u);
  EXPECT_EQ(p.patch_emitters[2 * 10 + 1], 7u);
  double total = 0;
  for (float p0 : p.default_probability) total += p0;
  EXPECT_NEAR(total, 1.0, 1e-6);
  EXPECT_NEAR(p.default_probability[0], 0.125, 1e-7);
  EXPECT_NEAR(p.default_probability[10], 0.06, 1e-7);
  // Clusters of at most 1/4: {emitter 0}, {emitter 1}, {2, 3, 4..6}.
  EXPECT_EQ(p.cluster_first, (std::vector<uint32_t>{0, 4, 8, 11}));
}

// A guide over build_emitter_patches' tables with a given learned distribution.
struct TestGuide {
  EmitterPatches patches;
  std::vector<float> cdf;
  std::vector<uint32_t> triangle_emitter;
  EmitterGuide guide(float mix) const {
    EmitterGuide g = emitter_guide_none();
    g.guided_probability = mix;
    g.cdf = cdf.data();
    g.patch_count = patches.count();
    g.emitter_patch = patches.emitter_patch.data();
    g.patch_emitters = patches.patch_emitters.data();
    g.triangle_emitter = triangle_emitter.data();
    return g;
  }
};

TEST(EmitterGuide, MixtureSamplesTheDensityItReports) {
  const std::vector<double> emitter_cdf = cdf_of({0.5, 0.3, 0.1, 0.04, 0.03, 0.02, 0.01});
  TestGuide t;
  t.patches = build_emitter_patches(emitter_cdf, 16, 4);
  // A learned distribution with zeros in it (a patch no sample reached) and a large peak.
  const std::vector<double> learned = {0.0, 3.0, 0.5, 0.0, 0.2, 0.2, 0.0, 1.0, 0.1, 0.0, 0.4};
  t.cdf = {0.0f};
  double sum = 0, total = 0;
  for (double l : learned) total += l;
  for (double l : learned) t.cdf.push_back(float((sum += l) / total));
  t.cdf.back() = 1.0f;
  const float mix = 0.6f;
  const EmitterGuide g = t.guide(mix);
  // The mixture's density relative to the default integrates to 1: sum of P0 x ratio.
  double normalisation = 0;
  for (uint k = 0; k < t.patches.count(); ++k)
    normalisation += t.patches.default_probability[k] * emitter_guide_ratio(emitter_cdf.data(), g, k);
  EXPECT_NEAR(normalisation, 1.0, 1e-5);
  // Cells: (emitter, child of its patch's sub-triangle one level down): expected probability
  // P0(patch) x ratio x (emitter's share of the patch's emitters) / 4.
  const uint emitters = 7;
  std::vector<double> observed(emitters * 4 * 64, 0.0), expected(observed.size(), 0.0);
  auto cell = [&](uint e, uint sub_index_within_emitter, uint child) { return (e * 64 + sub_index_within_emitter) * 4 + child; };
  const int n = 400000;
  for (uint e = 0; e < emitters; ++e) {
    const uint level = t.patches.emitter_patch[e] & 7, first = t.patches.emitter_patch[e] >> 3;
    for (uint s = 0; s < (1u << (2 * level)); ++s) {
      const uint patch = first + s;
      const uint pe0 = t.patches.patch_emitters[2 * patch], pe1 = t.patches.patch_emitters[2 * patch + 1];
      const double share = (emitter_cdf[e + 1] - emitter_cdf[e]) / (emitter_cdf[pe1] - emitter_cdf[pe0]);
      const double p = t.patches.default_probability[patch] * emitter_guide_ratio(emitter_cdf.data(), g, patch) * share;
      for (uint c = 0; c < 4; ++c) expected[cell(e, s, c)] = n * p / 4;
    }
  }
  std::mt19937 random(5);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  int mismatched = 0;
  for (int i = 0; i < n; ++i) {
    const EmitterPoint p = emitter_mixture_sample(emitter_cdf.data(), emitters, g, unit(random), unit(random), unit(random));
    const uint level = t.patches.emitter_patch[p.emitter] & 7;
    const uint fine = emitter_sub_triangle_of(level + 1, p.barycentrics.x, p.barycentrics.y);
    if (emitter_patch_of(g, p.emitter, p.barycentrics.x, p.barycentrics.y) != p.patch_index) ++mismatched;
    observed[cell(p.emitter, fine >> 2, fine & 3)] += 1;
  }
  EXPECT_EQ(mismatched, 0) << "the reported patch is not the point's";
  double dof = 0;
  const double chi = chi_square(observed, expected, dof);
  EXPECT_LT(chi, chi_square_limit(dof)) << "dof " << dof;
  // Without a learned component (mix 0) the mixture is the default sampling, number for number.
  const EmitterGuide off = t.guide(0.0f);
  for (int i = 0; i < 1000; ++i) {
    const float u = unit(random), u1 = unit(random), u2 = unit(random);
    float pmf;
    const EmitterPoint p = emitter_mixture_sample(emitter_cdf.data(), emitters, off, u, u1, u2);
    EXPECT_EQ(p.emitter, sample_cdf(emitter_cdf.data(), emitters, u, pmf));
    const vec2 b = sample_triangle_barycentrics(u1, u2);
    EXPECT_EQ(p.barycentrics.x, b.x);
    EXPECT_EQ(p.barycentrics.y, b.y);
  }
}

TEST(EmitterGuide, PunctualMixtureReportsTheProbabilityItSamples) {
  const std::vector<double> cdf = cdf_of({0.4, 0.3, 0.2, 0.06, 0.04});
  const std::vector<float> learned_cdf = {0.0f, 0.0f, 0.05f, 0.1f, 0.9f, 1.0f};  // light 0 never learned
  EmitterGuide g = emitter_guide_none();
  g.punctual_guided_probability = 0.5f;
  g.punctual_cdf = learned_cdf.data();
  g.punctual_count = 5;
  std::mt19937 random(3);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const int n = 200000;
  std::vector<double> observed(5, 0.0), expected(5, 0.0);
  std::vector<float> reported(5, -1.0f);
  for (int i = 0; i < n; ++i) {
    float probability;
    const uint light = punctual_mixture_sample(cdf.data(), 5, g, unit(random), probability);
    observed[light] += 1;
    reported[light] = probability;
  }
  for (uint i = 0; i < 5; ++i) {
    const double p = 0.5 * (cdf[i + 1] - cdf[i]) + 0.5 * (learned_cdf[i + 1] - learned_cdf[i]);
    expected[i] = n * p;
    EXPECT_NEAR(reported[i], p, 1e-6) << "light " << i;
  }
  double dof = 0;
  const double chi = chi_square(observed, expected, dof);
  EXPECT_LT(chi, chi_square_limit(dof));
}

IntegratorSettings settings(uint32_t spp, uint64_t seed, bool emitter_guiding) {
  IntegratorSettings s;
  s.spp = spp;
  s.seed = seed;
  s.emitter_guiding = emitter_guiding;
  return s;
}

TEST(EmitterGuiding, LearnsTheLightsARecordSees) {
  const testing::AtlasScene box = testing::box_with_lights_outside();
  const CpuReferenceIntegrator integrator(box.scene);
  IntegratorSettings s = settings(64, 1, true);
  size_t area_records = 0, punctual_records = 0, records = 0;
  s.inspect_emitter_guiding = [&](const EmitterGuidingCache& cache) {
    ASSERT_EQ(cache.punctual_count(), 2u);
    records = cache.record_count();
    // Patches of the lamp: its two triangles come first in the emitter list (scene order).
    const EmitterPatches& p = cache.patches();
    for (uint32_t r = 0; r < cache.record_count(); ++r) {
      double inside_area = 0, area = 0;
      for (uint32_t k = 0; k < p.count(); ++k) {
        area += cache.probability(r, k);
        if (p.patch_emitters[2 * k + 1] <= 2) inside_area += cache.probability(r, k);
      }
      // Records that learned nothing of the area lights (the ceiling's: it sees the single-sided
      // lamp from behind) sample by default.
      if (area > 0) {
        EXPECT_GT(inside_area, 0.8) << "record " << r;
        ++area_records;
      }
      EXPECT_GT(cache.punctual_probability(r, 1), 0.8) << "record " << r;
      ++punctual_records;
    }
  };
  integrator.bake(box.gbuffer, s);
  EXPECT_GT(punctual_records, 0u);
  EXPECT_GE(area_records, records * 3 / 4) << "records that learned the area lights";
}

// Guided against unguided, per region, over kSeeds seeds each; returns the median over regions of
// the relative standard error of the difference.
double expect_regions_agree(const std::string& label, const Scene& scene, const TexelGBuffer& gbuffer, uint32_t spp) {
  const CpuReferenceIntegrator integrator(scene);
  std::map<uint32_t, std::vector<double>> guided, unguided;
  for (int seed = 0; seed < kSeeds; ++seed) {
    const LightmapEstimate g = integrator.bake(gbuffer, settings(spp, uint64_t(seed), true));
    const LightmapEstimate u = integrator.bake(gbuffer, settings(spp, uint64_t(seed) + 1000, false));
    EXPECT_EQ(g.nonfinite_samples, 0u);
    EXPECT_EQ(u.nonfinite_samples, 0u);
    for (auto& [region, m] : testing::region_means(gbuffer, testing::luminance_means(g))) guided[region].push_back(m);
    for (auto& [region, m] : testing::region_means(gbuffer, testing::luminance_means(u))) unguided[region].push_back(m);
  }
  return testing::expect_region_means_agree("emitter guided", label, guided, unguided, kZLimit);
}

double sample_scene_agrees(const char* name, float density, uint32_t spp) {
  AtlasSettings atlas;
  atlas.texel_density = density;
  Diagnostics diagnostics;
  const PreparedScene p =
      prepare_scene_for_lighting(std::string(EXITANCE_SAMPLE_DIR "/") + name + ".gltf", "", atlas, diagnostics);
  return expect_regions_agree(name, p.scene, p.gbuffer, spp);
}

TEST(EmitterGuiding, BoxWithLightsOutsideAgreesWithUnguided) {
  const testing::AtlasScene box = testing::box_with_lights_outside();
  EXPECT_LT(kZLimit * expect_regions_agree("box", box.scene, box.gbuffer, 64), kDetectableBias)
      << "the test could not see a 10 % bias";
}

TEST(EmitterGuiding, CornellRoomAgreesWithUnguided) {
  EXPECT_LT(kZLimit * sample_scene_agrees("cornell_room", 2, 32), kDetectableBias) << "the test could not see a 10 % bias";
}

TEST(EmitterGuiding, AjarRoomAgreesWithUnguided) {
  EXPECT_LT(kZLimit * sample_scene_agrees("ajar_room", 4, 64), kDetectableBias) << "the test could not see a 10 % bias";
}

TEST(EmitterGuiding, BuildingAgreesWithUnguided) {
  EXPECT_LT(kZLimit * sample_scene_agrees("building", 0.5f, 64), kDetectableBias) << "the test could not see a 10 % bias";
}

TEST(EmitterGuiding, BitIdenticalPerSeedAndThreadCount) {
  const testing::AtlasScene box = testing::box_with_lights_outside();
  const CpuReferenceIntegrator integrator(box.scene);
  const LightmapEstimate a = integrator.bake(box.gbuffer, settings(24, 7, true));
  const LightmapEstimate b = integrator.bake(box.gbuffer, settings(24, 7, true));
  EXPECT_TRUE(testing::identical_texel_sums(a, b)) << "two runs with one seed differ";
  {
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    const LightmapEstimate c = integrator.bake(box.gbuffer, settings(24, 7, true));
    EXPECT_TRUE(testing::identical_texel_sums(a, c)) << "one thread and all threads differ";
  }
  const LightmapEstimate unguided = integrator.bake(box.gbuffer, settings(24, 7, false));
  EXPECT_FALSE(testing::identical_texel_sums(a, unguided)) << "emitter guiding must change the samples";
}

// The per-bounce mode (--integrator bounces) guides its direct-light samples: B_0's at texels and
// B_1's traced ones at gather hits. Both layers are linear in those samples, so per region their
// means agree with the unguided per-bounce mode's (two bounces, so no data-dependent tail length).
TEST(EmitterGuiding, PerBounceLayersAgreeWithUnguided) {
  const testing::AtlasScene box = testing::box_with_lights_outside();
  const CpuReferenceIntegrator integrator(box.scene);
  testing::RegionRuns guided[2], unguided[2];
  for (int seed = 0; seed < kSeeds; ++seed) {
    for (bool on : {true, false}) {
      IntegratorSettings s = settings(256, uint64_t(seed) + (on ? 0 : 1000), on);
      s.integrator = IntegratorMode::Bounces;
      s.max_bounces = 2;
      const LightmapEstimate e = integrator.bake(box.gbuffer, s);
      EXPECT_EQ(e.nonfinite_samples, 0u);
      if (on) {
        EXPECT_GT(e.emitter_guiding.records_sampling_learned, 0u);
      }
      for (int layer = 0; layer < 2; ++layer) testing::add_layer_regions(box.gbuffer, e, layer, (on ? guided : unguided)[layer]);
    }
  }
  for (int layer = 0; layer < 2; ++layer) {
    const double se = testing::expect_region_means_agree("emitter guided", "per-bounce layer " + std::to_string(layer),
                                                         guided[layer], unguided[layer], kZLimit);
    EXPECT_LT(kZLimit * se, kDetectableBias) << "layer " << layer << ": the test could not see a 10 % bias";
  }
}

TEST(EmitterGuiding, PerBounceBitIdenticalPerSeedAndThreadCount) {
  const testing::AtlasScene box = testing::box_with_lights_outside();
  const CpuReferenceIntegrator integrator(box.scene);
  IntegratorSettings s = settings(24, 7, true);
  s.integrator = IntegratorMode::Bounces;
  const LightmapEstimate a = integrator.bake(box.gbuffer, s);
  const LightmapEstimate b = integrator.bake(box.gbuffer, s);
  EXPECT_TRUE(testing::identical_texel_sums(a, b)) << "two runs with one seed differ";
  tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  const LightmapEstimate c = integrator.bake(box.gbuffer, s);
  EXPECT_TRUE(testing::identical_texel_sums(a, c)) << "one thread and all threads differ";
}

}  // namespace
}  // namespace exitance
