// The per-bounce mode (IntegratorMode::Bounces, issue 10) on the CPU backend: closed-form furnaces
// on a real atlas (so every gather reads texels), the layers summing to the total, the tail
// criterion at albedo 0.9, the on-the-fly fallback for hits without texels, and the bias against
// the path tracer on a smooth scene and on the Cornell room.
//
// Standard errors of scene means come from independent seeds: a bounce layer reads the layer
// below through a shared cache, so the texels' errors are correlated and the tracked per-texel
// variance does not add up to the variance of a mean over texels.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/bake/command/prepared_scene.h"
#include "exitance/common/bounce_gather.h"
#include "exitance/formats/lightmap_exr.h"
#include "exitance/runtime/core/bounce_tail.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "support/atlas_box.h"
#include "support/independent_estimates.h"

namespace exitance {
namespace {

constexpr double kZLimit = 4.0;  // two-sided, 16 seeds: p ~ 1e-3 under Student's t with 15 dof
constexpr int kSeeds = 16;

testing::AtlasScene furnace_box(float albedo, Vec3 le, float density) {
  const Vec3 emission[6] = {le, le, le, le, le, le};
  return testing::atlas_box(albedo, emission, density);
}

double mean_over_texels(const LightmapEstimate& e, int channel) {
  double sum = 0;
  for (size_t i = 0; i < e.texels.size(); ++i) sum += e.mean_total(i)[channel];
  return sum / double(e.texels.size());
}

IntegratorSettings bounce_settings(uint32_t spp, uint64_t seed, int max_bounces = -1) {
  IntegratorSettings s;
  s.integrator = IntegratorMode::Bounces;
  s.spp = spp;
  s.seed = seed;
  s.max_bounces = max_bounces;
  return s;
}

// Furnace of albedo rho, emission Le everywhere: B_k = rho^k Le exactly, so the bounces B_0..B_K sum
// to Le (1 - rho^(K+1)) / (1 - rho); no resolution bias (the field is constant).
void expect_furnace(float rho, int max_bounces, uint32_t spp) {
  const Vec3 le{1.0f, 0.5f, 0.25f};
  const testing::AtlasScene box = furnace_box(rho, le, 8);
  ASSERT_EQ(box.gbuffer.texels.size(), 6u * 64u);
  const CpuReferenceIntegrator integrator(box.scene);
  for (int c = 0; c < 3; ++c) {
    std::vector<double> ratios;
    for (int seed = 0; seed < kSeeds; ++seed) {
      const LightmapEstimate e = integrator.bake(box.gbuffer, bounce_settings(spp, uint64_t(seed), max_bounces));
      const int k = e.bounce_statistics.bounces;
      if (max_bounces >= 0) {
        EXPECT_EQ(k, max_bounces);
      }
      EXPECT_EQ(e.bounce_statistics.texelless_hits, 0u) << "a closed box: every gather hit has texels";
      EXPECT_EQ(e.nonfinite_samples, 0u);
      // With an automatic bounce count the tail beyond B_K is completed geometrically: the whole
      // answer Le / (1 - rho); a forced count is exactly the truncated sum.
      const double kept = e.bounce_statistics.tail_completed ? 1.0 : 1 - std::pow(double(rho), k + 1);
      EXPECT_EQ(e.bounce_statistics.tail_completed, max_bounces < 0);
      const double expected = le[c] * kept / (1 - rho);
      ratios.push_back(mean_over_texels(e, c) / expected);
    }
    const testing::MeanAndError s = testing::mean_and_standard_error(ratios);
    std::printf("[per-bounce] furnace rho %.2f bounces %d ch%d: estimate/exact %.5f SE %.2g z %+.2f\n", rho, max_bounces,
                c, s.mean, s.standard_error, (s.mean - 1) / s.standard_error);
    EXPECT_LE(std::fabs(s.mean - 1), kZLimit * s.standard_error) << "channel " << c;
    EXPECT_LT(s.standard_error, 0.01) << "too noisy to test anything";
  }
}

TEST(PerBounce, FurnaceReachesLeOverOneMinusAlbedo) {
  // 40 bounces at rho 0.5 leave 2^-41 of Le/(1-rho): the closed form itself.
  expect_furnace(0.5f, 40, 4);
}

TEST(PerBounce, FurnaceWithAutomaticBouncesMatchesTheSumOfTheBouncesRun) { expect_furnace(0.5f, -1, 16); }

// At rho = 0.9 the last bounce is 1/10 of the tail: the criterion must run ~22 bounces more than
// "stop when the last bounce is below the noise" would, and leave a truncated tail (exactly
// rho^(K+1) of the total here) below the noise of the total (half of it: kTailToNoise). The
// completed tail then restores the whole answer, Le / (1 - rho), within the noise.
TEST(PerBounce, TailCriterionRunsUntilTheTailIsBelowTheNoise) {
  const float rho = 0.9f;
  const testing::AtlasScene box = furnace_box(rho, {1, 1, 1}, 8);
  const CpuReferenceIntegrator integrator(box.scene);
  std::vector<double> ratios;
  for (int seed = 0; seed < 8; ++seed) {
    const LightmapEstimate e = integrator.bake(box.gbuffer, bounce_settings(16, uint64_t(seed)));
    const BounceGatherStatistics& b = e.bounce_statistics;
    const int k = b.bounces;
    const double truncated = std::pow(double(rho), k + 1);  // relative to Le / (1 - rho)
    const double noise = b.noise_rms;
    // The smallest k at which the last bounce, rho^k (1 - rho) relative, is below the noise.
    const int last_bounce_rule = int(std::ceil(std::log(noise / (1 - rho)) / std::log(double(rho))));
    std::printf("[per-bounce] rho 0.9 seed %d: %d bounces, ratio %.4f, truncated tail %.3g, tail estimate %.3g, "
                "noise %.3g; last-bounce rule would stop at %d\n",
                seed, k, b.ratio, truncated, b.tail_rms, noise, last_bounce_rule);
    EXPECT_TRUE(b.tail_below_noise);
    EXPECT_GT(noise, 0.0);
    EXPECT_NEAR(b.ratio, rho, 0.02);
    // The stop is at tail <= kTailToNoise x noise; factor 2 either way: the ratio and the per-texel
    // B_K it extrapolates are estimates themselves.
    EXPECT_LE(truncated, 2 * kTailToNoise * noise) << "stopped with the tail above the noise";
    EXPECT_GE(std::pow(double(rho), k), kTailToNoise * noise / 2) << "ran bounces the noise could not see";
    EXPECT_GE(k, last_bounce_rule + 15);
    EXPECT_TRUE(b.tail_completed);
    ratios.push_back(mean_over_texels(e, 0) * (1 - rho));
  }
  const testing::MeanAndError s = testing::mean_and_standard_error(ratios);
  std::printf("[per-bounce] rho 0.9: estimate with the completed tail / closed form %.5f SE %.2g\n", s.mean, s.standard_error);
  EXPECT_LE(std::fabs(s.mean - 1), kZLimit * s.standard_error + 1e-6);
}

TEST(PerBounce, LayersSumToTheTotal) {
  const testing::AtlasScene box = furnace_box(0.7f, {1, 2, 3}, 4);
  const LightmapEstimate e = CpuReferenceIntegrator(box.scene).bake(box.gbuffer, bounce_settings(8, 3));
  const int layers = e.bounce_statistics.bounces + 1;
  ASSERT_GE(layers, 3);
  EXPECT_EQ(e.recorded_bounces, layers);
  ASSERT_EQ(e.bounce_statistics.samples.size(), size_t(layers));
  for (uint32_t n : e.bounce_statistics.samples) EXPECT_EQ(n, 8u);
  for (size_t i = 0; i < e.texels.size(); ++i) {
    Vec3 sum{0, 0, 0};
    for (int k = 0; k < layers; ++k) sum += e.mean_bounce(k, i);
    const Vec3 total = e.mean_total(i), direct = e.mean_direct(i), b0 = e.mean_bounce(0, i);
    for (int c = 0; c < 3; ++c) {
      ASSERT_NEAR(sum[c], total[c], 1e-5f * total[c]) << "texel " << i;
      ASSERT_NEAR(direct[c], b0[c], 1e-6f * b0[c]) << "texel " << i;
    }
    EXPECT_GT(e.variance_of_mean(i)[0], 0.0f);
  }
}

// A time budget ramps passes over all layers: later layers have fewer samples, the budget holds,
// the layers still sum to the total. A target error stops the whole lightmap when every texel meets
// it and the tail is below the noise.
TEST(PerBounce, TimeBudgetAndTargetError) {
  const testing::AtlasScene box = furnace_box(0.7f, {1, 1, 1}, 8);
  const CpuReferenceIntegrator integrator(box.scene);
  IntegratorSettings timed = bounce_settings(0, 5);
  timed.time_budget_seconds = 0.3;
  const LightmapEstimate e = integrator.bake(box.gbuffer, timed);
  const BounceGatherStatistics& b = e.bounce_statistics;
  std::printf("[per-bounce] 0.3 s budget: %.3f s, %d bounces, samples of B_0 %u, of B_%d %u\n", e.seconds, b.bounces,
              b.samples.front(), b.bounces, b.samples.back());
  // How well the budget is kept is per_bounce_budget_tests' (a virtual clock): a wall-clock bound
  // here failed under a loaded ctest -j2 (three test runs on 2 cores).
  ASSERT_GE(b.bounces, 2);
  EXPECT_GT(b.samples.front(), 0u);
  for (size_t k = 1; k < b.samples.size(); ++k) EXPECT_LE(b.samples[k], b.samples[k - 1]);
  EXPECT_GT(b.samples.back(), 0u);
  for (size_t i = 0; i < e.texels.size(); ++i) {
    float sum = 0;
    for (int k = 0; k <= b.bounces; ++k) sum += e.mean_bounce(k, i)[1];
    ASSERT_NEAR(sum, e.mean_total(i)[1], 1e-5f * sum);
  }

  IntegratorSettings target = bounce_settings(0, 6);
  target.target_relative_error = 0.03;
  const LightmapEstimate t = integrator.bake(box.gbuffer, target);
  EXPECT_TRUE(t.bounce_statistics.tail_below_noise);
  for (size_t i = 0; i < t.texels.size(); ++i) ASSERT_TRUE(t.relative_error_below(i, 0.03)) << "texel " << i;

  // A texel that never sees light (under a tile lying on the floor of a lit box) has no relative
  // error to meet: the run must still end, in both modes, well before a sample cap that only a run
  // the black texel kept going would reach.
  testing::AtlasScene covered = furnace_box(0.5f, {1, 1, 1}, 4);
  const uint32_t tile = testing::add_material(covered.scene, {0.5f, 0.5f, 0.5f});
  testing::add_quad(covered.scene, {0.2f, 1e-4f, 0.2f}, {0, 0, 0.6f}, {0.6f, 0, 0}, tile);  // faces up
  LiveTexel under = covered.gbuffer.texels.front();
  under.position = {0.5f, 0.0f, 0.5f};
  under.geometric_normal = under.shading_normal = {0, 1, 0};
  covered.gbuffer.texels.push_back(under);
  constexpr uint32_t kCap = 1u << 14;
  IntegratorSettings bounded = target;
  bounded.spp = kCap;
  for (IntegratorMode mode : {IntegratorMode::Bounces, IntegratorMode::Path}) {
    bounded.integrator = mode;
    const LightmapEstimate c = CpuReferenceIntegrator(covered.scene).bake(covered.gbuffer, bounded);
    const size_t black = covered.gbuffer.texels.size() - 1;
    EXPECT_EQ(c.mean_total(black)[0], 0.0f);
    EXPECT_LT(c.texels[black].samples, kCap) << "the black texel kept the target-error run going, mode "
                                              << int(mode);
  }
}

// Under a time budget the last layer pass may give one more sample to part of the texels
// (core/partial_layer_pass.h): every texel's B_0 then has m or m + 1 samples, and a texel's B_0 is
// exactly what a --spp bake of its own count gives there (B_0's random streams are per texel and
// sample, and it reads no cache). Where the budget happened to end on a whole pass, only m is seen.
// B_0 alone (--bounces 0), so the last pass is B_0's.
TEST(PerBounce, TimeBudgetTexelsHoldTheirOwnSampleMeans) {
  const testing::AtlasScene box = furnace_box(0.7f, {1, 1, 1}, 8);
  const CpuReferenceIntegrator integrator(box.scene);
  IntegratorSettings timed = bounce_settings(0, 9, 0);
  timed.time_budget_seconds = 0.05;
  const LightmapEstimate e = integrator.bake(box.gbuffer, timed);
  const BounceGatherStatistics& b = e.bounce_statistics;
  const uint32_t m = b.samples.front();
  ASSERT_GE(m, 1u);
  std::printf("[per-bounce] 0.05 s budget: B_0 %u samples, %llu texels with one more\n", m,
              (unsigned long long)b.texels_with_one_more.front());
  for (uint32_t count : {m, m + 1}) {
    const LightmapEstimate fixed = integrator.bake(box.gbuffer, bounce_settings(count, 9, 0));
    for (size_t i = 0; i < e.texels.size(); ++i) {
      ASSERT_TRUE(e.texels[i].samples == m || e.texels[i].samples == m + 1) << "texel " << i;
      if (e.texels[i].samples != count) continue;
      for (int c = 0; c < 3; ++c) ASSERT_FLOAT_EQ(e.mean_bounce(0, i)[c], fixed.mean_bounce(0, i)[c]) << "texel " << i;
    }
  }
  uint64_t with_one_more = 0;
  for (const TexelAccumulator& t : e.texels) with_one_more += t.samples == m + 1 ? 1 : 0;
  EXPECT_EQ(with_one_more, b.texels_with_one_more.front());
}

// A hand-made G-buffer has no atlas rectangles: every gather hit is estimated on the fly, which
// makes the mode an unbiased path tracer split by bounce. Its layers are independent samples, so
// here the tracked variance is the variance of the texel means.
TEST(PerBounce, HitsWithoutTexelsAreEstimatedOnTheFly) {
  const testing::AnalyticScene a = testing::white_furnace(0.5f);
  IntegratorSettings settings = bounce_settings(64, 11, 30);
  settings.trace_first_bounce = false;  // every layer tries its lookup (a traced B_1 never does)
  const LightmapEstimate e = CpuReferenceIntegrator(a.scene).bake(a.gbuffer, settings);
  EXPECT_EQ(e.bounce_statistics.texelless_hits, e.bounce_statistics.gathers);
  EXPECT_GT(e.bounce_statistics.gathers, 0u);
  std::vector<size_t> texels(a.gbuffer.texels.size());
  for (size_t i = 0; i < texels.size(); ++i) texels[i] = i;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> expected(a.exact);
    for (double& v : expected) v *= a.colour[c];
    const auto g = testing::compare_group(e, texels, expected, c);
    std::printf("[per-bounce] no atlas, furnace 0.5 ch%d: exact %.5g estimate %.5g SE %.3g z %+.2f\n", c, g.expected,
                g.estimate, g.standard_error, g.z());
    EXPECT_LE(std::fabs(g.z()), kZLimit);
    EXPECT_LT(g.standard_error, 0.02 * g.expected);
  }
}

// A box lit by its ceiling: smooth irradiance over large faces (8 texels per side). The mean per
// face of the per-bounce mode against the path tracer: the bilinear cache's bias must stay within
// the noise of 16 seeds of each (a few tenths of a percent here). 30 bounces (0.6^31 ~ 1e-7 left):
// the automatic criterion stops when the tail is below the noise of a texel, which is far above
// the noise of a face mean over 16 seeds, so its truncation would show here.
TEST(PerBounce, SmoothSceneAgreesWithThePathTracerWithinNoise) {
  const Vec3 black{0, 0, 0}, le{4, 4, 4};
  const Vec3 emission[6] = {black, le, black, black, black, black};
  const testing::AtlasScene box = testing::atlas_box(0.6f, emission, 8);
  const CpuReferenceIntegrator integrator(box.scene);
  auto face_means = [&](const LightmapEstimate& e) {
    std::vector<double> sum(6, 0.0), count(6, 0.0);
    for (size_t i = 0; i < e.texels.size(); ++i) {
      sum[box.gbuffer.texels[i].instance] += e.mean_total(i)[0];
      count[box.gbuffer.texels[i].instance] += 1;
    }
    for (int f = 0; f < 6; ++f) sum[size_t(f)] /= count[size_t(f)];
    return sum;
  };
  std::vector<std::vector<double>> bounce_runs(6), path_runs(6);
  for (int seed = 0; seed < kSeeds; ++seed) {
    const std::vector<double> b = face_means(integrator.bake(box.gbuffer, bounce_settings(16, uint64_t(seed), 30)));
    IntegratorSettings path;
    path.spp = 64;
    path.seed = uint64_t(seed);
    const std::vector<double> p = face_means(integrator.bake(box.gbuffer, path));
    for (int f = 0; f < 6; ++f) bounce_runs[size_t(f)].push_back(b[size_t(f)]), path_runs[size_t(f)].push_back(p[size_t(f)]);
  }
  for (int f = 0; f < 6; ++f) {
    const testing::MeanAndError b = testing::mean_and_standard_error(bounce_runs[size_t(f)]), p = testing::mean_and_standard_error(path_runs[size_t(f)]);
    const double se = std::hypot(b.standard_error, p.standard_error), z = (b.mean - p.mean) / se;
    std::printf("[per-bounce] ceiling-lit box face %d: bounces %.5f path %.5f difference %+.3f%% SE %.3f%% z %+.2f\n", f,
                b.mean, p.mean, 100 * (b.mean - p.mean) / p.mean, 100 * se / p.mean, z);
    EXPECT_LE(std::fabs(z), kZLimit) << "face " << f;
    EXPECT_LT(se, 0.01 * p.mean);
  }
}

// A box lit by a small lamp just under its ceiling: the walls' direct light changes within a texel
// near the top (the lamp is nearly in the ceiling's plane). B_1 traced at its gather hits is an
// unbiased estimate of the first bounce, so its face means must agree with the path tracer's bounce
// layer 1 within the noise of 16 seeds of each; B_1 read from the B_0 lightmap (cached) is printed
// beside it, with its resolution bias.
TEST(PerBounce, TracedFirstBounceAgreesWithThePathTracersFirstBounce) {
  const Vec3 black{0, 0, 0};
  const Vec3 emission[6] = {black, black, black, black, black, black};
  const testing::AtlasScene box = testing::atlas_box(0.6f, emission, 8, 0.1f, {200, 200, 200});
  const CpuReferenceIntegrator integrator(box.scene);
  auto face_means_of_bounce_one = [&](const LightmapEstimate& e) {
    std::vector<double> sum(6, 0.0), count(6, 0.0);
    for (size_t i = 0; i < e.texels.size(); ++i) {
      const uint32_t face = box.gbuffer.texels[i].instance;
      if (face >= 6) continue;  // the lamp
      sum[face] += e.mean_bounce(1, i)[0];
      count[face] += 1;
    }
    for (int f = 0; f < 6; ++f) sum[size_t(f)] /= count[size_t(f)];
    return sum;
  };
  std::vector<std::vector<double>> traced(6), cached(6), path(6);
  for (int seed = 0; seed < kSeeds; ++seed) {
    IntegratorSettings bounces = bounce_settings(16, uint64_t(seed), 2);
    const std::vector<double> t = face_means_of_bounce_one(integrator.bake(box.gbuffer, bounces));
    bounces.trace_first_bounce = false;
    const std::vector<double> c = face_means_of_bounce_one(integrator.bake(box.gbuffer, bounces));
    IntegratorSettings path_settings;
    path_settings.spp = 64;
    path_settings.seed = uint64_t(seed);
    const std::vector<double> p = face_means_of_bounce_one(integrator.bake(box.gbuffer, path_settings));
    for (size_t f = 0; f < 6; ++f) traced[f].push_back(t[f]), cached[f].push_back(c[f]), path[f].push_back(p[f]);
  }
  for (size_t f = 0; f < 6; ++f) {
    const testing::MeanAndError t = testing::mean_and_standard_error(traced[f]), c = testing::mean_and_standard_error(cached[f]),
                                p = testing::mean_and_standard_error(path[f]);
    const double se = std::hypot(t.standard_error, p.standard_error), z = (t.mean - p.mean) / se;
    std::printf("[per-bounce] lamp-lit box face %zu, bounce 1: path %.5f traced %+.3f%% (z %+.2f) cached %+.3f%% "
                "(z %+.2f)\n", f, p.mean, 100 * (t.mean - p.mean) / p.mean, z, 100 * (c.mean - p.mean) / p.mean,
                (c.mean - p.mean) / std::hypot(c.standard_error, p.standard_error));
    EXPECT_LE(std::fabs(z), kZLimit) << "face " << f;
    EXPECT_LT(se, 0.02 * p.mean) << "face " << f;
  }
}

// The Cornell room: the bias is measured and reported (bench/results/per-bounce.md has the
// figures); what is asserted is what holds whatever the texel size: no NaN, every gather hit has
// texels, layers that sum to the total, and the tail criterion met.
TEST(PerBounce, CornellRoomAgainstThePathTracer) {
  AtlasSettings atlas;
  atlas.texel_density = 4;
  Diagnostics diagnostics;
  const PreparedScene p = prepare_scene_for_lighting(EXITANCE_SAMPLE_DIR "/cornell_room.gltf", "", atlas, diagnostics);
  const CpuReferenceIntegrator integrator(p.scene);
  const LightmapEstimate bounces = integrator.bake(p.gbuffer, bounce_settings(64, 1));
  IntegratorSettings path_settings;
  path_settings.spp = 256;
  path_settings.seed = 2;
  const LightmapEstimate path = integrator.bake(p.gbuffer, path_settings);
  const BounceGatherStatistics& b = bounces.bounce_statistics;
  EXPECT_EQ(bounces.nonfinite_samples, 0u);
  EXPECT_TRUE(b.tail_below_noise);
  EXPECT_EQ(b.texelless_hits, 0u);
  double rel_mse = 0, path_noise = 0, bounce_noise = 0, sum_bounces = 0, sum_path = 0;
  for (size_t i = 0; i < p.gbuffer.texels.size(); ++i) {
    const Vec3 x = bounces.mean_total(i), r = path.mean_total(i);
    Vec3 layers{0, 0, 0};
    for (int k = 0; k < bounces.recorded_bounces; ++k) layers += bounces.mean_bounce(k, i);
    for (int c = 0; c < 3; ++c) {
      ASSERT_NEAR(layers[c], x[c], 1e-5f * x[c] + 1e-7f);
      const double w = 1.0 / (double(r[c]) * r[c] + 1e-3);
      rel_mse += (double(x[c]) - r[c]) * (double(x[c]) - r[c]) * w;
      path_noise += path.variance_of_mean(i)[c] * w;
      bounce_noise += bounces.variance_of_mean(i)[c] * w;
      sum_bounces += x[c];
      sum_path += r[c];
    }
  }
  const double values = 3.0 * double(p.gbuffer.texels.size());
  std::printf("[per-bounce] cornell_room: %d bounces, relMSE against the path tracer %.3g (path noise %.3g, "
              "per-bounce tracked noise %.3g), mean E/pi ratio %.4f\n",
              b.bounces, rel_mse / values, path_noise / values, bounce_noise / values, sum_bounces / sum_path);
  ::testing::Test::RecordProperty("rel_mse_vs_path", std::to_string(rel_mse / values));
}

// bake --integrator bounces --bounce-layers on the CPU reference: the page holds every bounce
// layer, which sum to R,G,B.
TEST(PerBounce, BakeWritesEveryBounceLayer) {
  namespace fs = std::filesystem;
  const fs::path out = fs::temp_directory_path() / ("exitance-test-per-bounce-" + std::to_string(::getpid()));
  fs::remove_all(out);
  BakeOptions options;
  options.input = EXITANCE_SAMPLE_DIR "/cornell_room.gltf";
  options.output = out.string();
  options.atlas.texel_density = 4;
  options.lighting.spp = 16;
  options.lighting.integrator = IntegratorMode::Bounces;
  options.bounce_layers = true;
  options.probes_enabled = false;
  options.svo_enabled = false;
  options.backend.name = "cpu";
  Diagnostics diagnostics;
  run_bake(options, diagnostics);
  std::ifstream manifest_file(out / "manifest.json");
  const nlohmann::json manifest = nlohmann::json::parse(manifest_file);
  const formats::LightmapImage page =
      formats::read_lightmap_exr((out / manifest["pages"][0]["file"].get<std::string>()).string());
  int layers = 0;
  while (page.channels.count("bounce" + std::to_string(layers) + ".R")) ++layers;
  EXPECT_GE(layers, 4);
  const std::vector<float>& r = page.channels.at("R");
  const std::vector<float>& a = page.channels.at("A");
  for (size_t i = 0; i < r.size(); ++i) {
    if (!(a[i] > 0)) continue;
    float sum = 0;
    for (int k = 0; k < layers; ++k) sum += page.channels.at("bounce" + std::to_string(k) + ".R")[i];
    ASSERT_NEAR(sum, r[i], 1e-5f * r[i] + 1e-6f) << "texel " << i;
  }
  fs::remove_all(out);
}

// Both backends refuse --directional sh1 with the mode (it estimates no L1 layers) instead of
// leaving them empty. (The Vulkan mode itself: tests/crosscheck/vulkan_bounce_crosscheck_test.cpp.)
TEST(PerBounce, BothBackendsRefuseDirectionalLayers) {
  const testing::AtlasScene box = furnace_box(0.5f, {1, 1, 1}, 4);
  IntegratorSettings settings = bounce_settings(4, 1);
  settings.directional = DirectionalMode::Sh1;
  EXPECT_THROW(CpuReferenceIntegrator(box.scene).bake(box.gbuffer, settings), std::invalid_argument);
  const std::vector<VulkanDeviceInfo> devices = enumerate_vulkan_devices();
  if (std::none_of(devices.begin(), devices.end(), [](const VulkanDeviceInfo& d) { return d.usable; }))
    GTEST_SKIP() << "no usable Vulkan device";
  const std::unique_ptr<VulkanIntegrator> vulkan = VulkanIntegrator::create(make_lighting_scene(box.scene));
  EXPECT_THROW(vulkan->bake(box.gbuffer, settings), std::invalid_argument);
}

// bounce_gather.h as C++ (the same text compiles as GLSL: shaders/checks/bounce_gather_check.comp).
TEST(BounceGatherMath, FootprintAndTail) {
  // The centre of texel (5, 2) of a 16 x 8 page reads that texel alone.
  BilinearFootprint f = bilinear_footprint(vec2(5.5f / 16, 2.5f / 8), 16, 8);
  EXPECT_EQ(f.x0, 5);
  EXPECT_EQ(f.y0, 2);
  EXPECT_NEAR(bilinear_weight(f, 0, 0), 1.0f, 1e-5f);
  // Halfway between the centres of (5, 2) and (6, 3): four equal weights summing to 1.
  f = bilinear_footprint(vec2(6.0f / 16, 3.0f / 8), 16, 8);
  EXPECT_EQ(f.x0, 5);
  EXPECT_EQ(f.y0, 2);
  float sum = 0;
  for (int dy = 0; dy <= 1; ++dy)
    for (int dx = 0; dx <= 1; ++dx) {
      EXPECT_NEAR(bilinear_weight(f, dx, dy), 0.25f, 1e-5f);
      sum += bilinear_weight(f, dx, dy);
    }
  EXPECT_NEAR(sum, 1.0f, 1e-6f);
  // The left edge of the page: the footprint starts at column -1 (left out by the lookup).
  EXPECT_EQ(bilinear_footprint(vec2(0.0f, 0.5f), 16, 8).x0, -1);
  const Vec2 uv = lightmap_page_uv(vec2(0.5f, 0.25f), Vec4(0.5f, 0.25f, 0.125f, 0.5f));
  EXPECT_FLOAT_EQ(uv.x, 0.375f);
  EXPECT_FLOAT_EQ(uv.y, 0.5625f);
  EXPECT_FLOAT_EQ(geometric_tail_factor(0.5f), 1.0f);
  EXPECT_NEAR(geometric_tail_factor(0.99f), 99.0f, 1e-3f);  // the tail is ~100x the last bounce
  EXPECT_FLOAT_EQ(geometric_tail_factor(0.0f), 0.0f);
  EXPECT_TRUE(std::isinf(geometric_tail_factor(1.0f)));
}

TEST(BounceTail, GeometricSeriesAgainstItsNoise) {
  BounceTailInputs in;
  const size_t n = 10;
  in.area.assign(n, 1.0);
  in.previous_bounce.assign(n, 0.2);
  in.last_bounce.assign(n, 0.1);   // r = 0.5: the tail is 0.1 more
  in.total.assign(n, 1.0);
  in.total_variance.assign(n, 0.0);
  BounceTail t = estimate_bounce_tail(in);
  EXPECT_NEAR(t.ratio, 0.5, 1e-12);
  EXPECT_NEAR(t.tail_rms, 0.1 / std::sqrt(1.001), 1e-6);
  EXPECT_FALSE(t.below_noise);
  in.total_variance.assign(n, 0.11 * 0.11);  // noise 11 % > tail 10 %, but not twice the tail
  EXPECT_FALSE(estimate_bounce_tail(in).below_noise);
  in.total_variance.assign(n, 0.21 * 0.21);  // noise 21 %: the tail is below half of it
  EXPECT_TRUE(estimate_bounce_tail(in).below_noise);
  in.last_bounce_variance.assign(n, 0.1 * 0.1);  // B_k no larger than its own noise: nothing left
  EXPECT_TRUE(estimate_bounce_tail(in).below_noise);
  in.last_bounce_variance.clear();
  in.last_bounce.assign(n, 0.2);               // no decay: r = 1, the tail is unbounded
  t = estimate_bounce_tail(in);
  EXPECT_TRUE(std::isinf(t.tail_rms));
  EXPECT_FALSE(t.below_noise);
  in.last_bounce.assign(n, 0.0);               // nothing bounced on: done
  EXPECT_TRUE(estimate_bounce_tail(in).below_noise);
}

}  // namespace
}  // namespace exitance
