// The runtime's RefreshSession (runtime/include/exitance/runtime/refresh/refresh_session.h) on a
// bundle baked here, on lavapipe in CI: samples added over several refresh calls are the bake's
// samples bit for bit; a restart drops every sample; the estimated relMSE a refresh reports is
// within 2x of the relMSE measured against a converged lightmap; an engine's adopted device gives
// the same results; light subpaths switched between refreshes; bad budgets are refused.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/runtime/refresh/refresh_session.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "exitance/runtime/world_box.h"
#include "support/engine_vulkan_device.h"
#include "support/vulkan_device_available.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;

using testing::has_vulkan_device;

// The Cornell room baked once (CPU backend: the session must not depend on how it was baked).
const fs::path& baked_bundle() {
  static const fs::path bundle = [] {
    const fs::path dir = fs::temp_directory_path() / ("exitance-refresh-test-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    BakeOptions options;
    options.input = std::string(EXITANCE_SAMPLE_DIR) + "/cornell_room.gltf";
    options.output = (dir / "cornell.bake").string();
    options.backend.name = "cpu";
    options.atlas.texel_density = 5;
    options.lighting.spp = 4;
    options.lighting.seed = 3;
    options.probes_enabled = false;
    Diagnostics diagnostics;
    run_bake(options, diagnostics);
    return dir / "cornell.bake";
  }();
  return bundle;
}

void expect_same_sums(const LightmapEstimate& a, const LightmapEstimate& b) {
  ASSERT_EQ(a.texels.size(), b.texels.size());
  size_t differing = 0;
  for (size_t i = 0; i < a.texels.size(); ++i) {
    differing += a.texels[i].samples != b.texels[i].samples;
    for (int c = 0; c < 3; ++c)
      differing += a.texels[i].total[c] != b.texels[i].total[c] || a.texels[i].total_squared[c] != b.texels[i].total_squared[c];
  }
  EXPECT_EQ(differing, 0u);
  EXPECT_EQ(a.bounces, b.bounces);
}

TEST(RefreshSession, FramesAddUpToTheBakesSamplesBitForBit) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  auto session = RefreshSession::open(baked_bundle().string());
  uint32_t done = 0;
  for (uint32_t cap : {1u, 3u, 6u}) {
    const RefreshReport r = session->refresh({0, cap});
    EXPECT_EQ(r.samples_added, cap - done);
    EXPECT_EQ(r.samples_per_texel, cap);
    EXPECT_TRUE(r.capped);
    EXPECT_GT(r.rays, 0u);
    done = cap;
  }
  EXPECT_EQ(session->refresh({0, 6}).samples_added, 0u);  // capped: nothing more
  const LightmapEstimate progressive = session->lightmap();
  IntegratorSettings settings = session->settings();
  settings.spp = 6;
  const LightmapEstimate baked = session->integrator().bake(session->persisted().gbuffer, settings);
  expect_same_sums(progressive, baked);
}

// Budgets smaller than one sample of the lightmap: each call refreshes part of the texels, the next
// goes on where it stopped, and after the calls that add up to N samples of every texel the sums
// equal a bake's N samples bit for bit (each texel took its samples in order).
TEST(RefreshSession, CallsShorterThanASampleAddUpToTheBakesSamples) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  auto session = RefreshSession::open(baked_bundle().string());
  const uint64_t texels = session->persisted().gbuffer.texels.size();
  ASSERT_GT(texels, 8u);
  const uint64_t third = (texels + 2) / 3;  // three calls per sample, the last one shorter
  RefreshReport r = session->refresh({0, 0, third});
  EXPECT_EQ(r.samples_per_texel, 0u);  // a third of the texels have one sample
  EXPECT_GT(r.rays, 0u);
  EXPECT_EQ(session->lightmap().texels[0].samples, 1u);
  EXPECT_EQ(session->lightmap().texels[texels - 1].samples, 0u);
  r = session->refresh({0, 0, third});
  r = session->refresh({0, 0, texels - 2 * third});
  EXPECT_EQ(r.samples_per_texel, 1u);
  for (const TexelAccumulator& t : session->lightmap().texels) ASSERT_EQ(t.samples, 1u);
  EXPECT_EQ(r.samples_added, 1u);
  r = session->refresh({0, 0, texels + third});  // one whole sample, then a third of the next
  EXPECT_EQ(r.samples_per_texel, 2u);
  r = session->refresh({0, 2, 10 * texels});  // the cap counts whole samples: 2 reached, nothing added
  EXPECT_EQ(r.samples_per_texel, 2u);
  r = session->refresh({0, 0, 2 * texels - third});  // what is left of the third sample, then a whole fourth
  EXPECT_EQ(r.samples_per_texel, 4u);
  const LightmapEstimate progressive = session->lightmap();
  for (const TexelAccumulator& t : progressive.texels) ASSERT_EQ(t.samples, 4u);
  IntegratorSettings settings = session->settings();
  settings.spp = 4;
  expect_same_sums(progressive, session->integrator().bake(session->persisted().gbuffer, settings));
}

TEST(RefreshSession, RestartDropsEverySample) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  auto session = RefreshSession::open(baked_bundle().string());
  session->refresh({0, 3});
  const LightmapEstimate first_two = [&] {
    auto other = RefreshSession::open(baked_bundle().string());
    other->refresh({0, 2});
    return other->lightmap();
  }();
  session->restart();
  const LightmapEstimate empty = session->lightmap();
  for (const TexelAccumulator& t : empty.texels) {
    ASSERT_EQ(t.samples, 0u);
    ASSERT_EQ(t.total[0] + t.total[1] + t.total[2], 0.0);
  }
  session->refresh({0, 2});
  expect_same_sums(session->lightmap(), first_two);
}

// relMSE as bench/time_to_error.cpp measures it, against a reference, minus the reference's own
// expected relMSE (its noise), which the estimate does not include.
double measured_relative_mse(const LightmapEstimate& x, const LightmapEstimate& reference) {
  double sum = 0, reference_noise = 0;
  size_t count = 0;
  for (size_t i = 0; i < x.texels.size(); ++i) {
    const Vec3 a = x.mean_total(i), r = reference.mean_total(i), rv = reference.variance_of_mean(i);
    for (int c = 0; c < 3; ++c) {
      const double d = double(a[c]) - r[c], denominator = double(r[c]) * r[c] + 1e-3;
      sum += d * d / denominator;
      reference_noise += rv[c] / denominator;
    }
    count += 3;
  }
  return (sum - reference_noise) / double(count);
}

TEST(RefreshSession, EstimatedErrorIsWithinTwiceTheMeasured) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  RefreshSessionOptions reference_options;
  reference_options.seed = 1001;  // independent of the estimate's samples
  auto reference_session = RefreshSession::open(baked_bundle().string(), reference_options);
  reference_session->refresh({0, 256});
  const LightmapEstimate reference = reference_session->lightmap();

  auto session = RefreshSession::open(baked_bundle().string());
  for (uint32_t spp : {8u, 32u}) {
    session->refresh({0, spp});
    const LightmapEstimate estimate = session->lightmap();
    const double estimated = RefreshSession::estimated_relative_mse(estimate);
    const double measured = measured_relative_mse(estimate, reference);
    SCOPED_TRACE("spp " + std::to_string(spp) + ": estimated relMSE " + std::to_string(estimated) + ", measured " +
                 std::to_string(measured));
    std::printf("spp %u: estimated relMSE %.5f, measured %.5f (ratio %.3f)\n", spp, estimated, measured, estimated / measured);
    EXPECT_GT(measured, 0);
    EXPECT_LE(estimated, 2 * measured);
    EXPECT_GE(estimated, 0.5 * measured);
  }
}

// An engine hands over its own device and queue (validation on, every message a failure): the
// session's frames and an edit give what a session on its own device gives, bit for bit, and the
// engine's device outlives the session.
TEST(RefreshSession, OnAnEnginesDeviceGivesTheSameResults) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const char* edit = R"({"edits": [{"material": "CeilingLight", "emissiveStrength": 3.0}]})";
  auto own = RefreshSession::open(baked_bundle().string());
  own->refresh({0, 2});
  own->apply_edits(parse_scene_edits(edit, "edit.json"));
  own->refresh({0, 3});
  const LightmapEstimate expected = own->lightmap();

  testing::EngineDevice engine(own->integrator().device().index, vulkan_required_features());
  for (int round = 0; round < 2; ++round) {  // the second: the first session took nothing with it
    RefreshSessionOptions options;
    options.device = engine.options();
    auto adopted = RefreshSession::open(baked_bundle().string(), options);
    EXPECT_NE(adopted->integrator().device_description().find("adopted"), std::string::npos);
    adopted->refresh({0, 2});
    adopted->apply_edits(parse_scene_edits(edit, "edit.json"));
    adopted->refresh({0, 3});
    expect_same_sums(adopted->lightmap(), expected);
  }
}

// Estimated relMSE over a subset of texels; infinity while one of them has fewer than 2 samples
// (the estimate leaves those out).
double subset_relative_mse(const LightmapEstimate& all, const std::vector<uint32_t>& texels) {
  LightmapEstimate subset;
  for (uint32_t i : texels) {
    if (all.texels[i].samples < 2) return std::numeric_limits<double>::infinity();
    subset.texels.push_back(all.texels[i]);
  }
  return RefreshSession::estimated_relative_mse(subset);
}

// The courtyard baked once (its pavilion is a small part of it).
const fs::path& courtyard_bundle() {
  static const fs::path bundle = [] {
    const fs::path dir = baked_bundle().parent_path();
    BakeOptions options;
    options.input = std::string(EXITANCE_SAMPLE_DIR) + "/courtyard.gltf";
    options.output = (dir / "courtyard.bake").string();
    options.backend.name = "cpu";
    options.sky = "0.3,0.4,0.5";
    options.atlas.texel_density = 2;
    options.lighting.spp = 1;
    options.probes_enabled = false;
    Diagnostics diagnostics;
    run_bake(options, diagnostics);
    return dir / "courtyard.bake";
  }();
  return bundle;
}

// Refresh calls of one sample of every texel each (a deterministic budget) after moving the
// pavilion 3 m: how many calls until the texels within 3 m of it (before or after), and the
// others, reach the error the whole lightmap had at 8 samples before the edit (fewer than the 16
// prioritized samples).
struct CallsToError {
  int near = 0, far = 0;
};
CallsToError calls_to_error(uint32_t priority_samples) {
  RefreshSessionOptions options;
  options.priority_samples = priority_samples;
  auto session = RefreshSession::open(courtyard_bundle().string(), options);
  session->refresh({0, 8});
  const double target = RefreshSession::estimated_relative_mse(session->lightmap());
  const Scene& before = session->persisted().scene;
  WorldBox pavilion;
  for (const Instance& instance : before.instances)
    if (instance.name == "Pavilion") pavilion.grow(instance_world_box(before, instance));
  Vec3 lo = pavilion.lo, hi = pavilion.hi;
  session->apply_edits(parse_scene_edits(R"({"edits": [{"node": "Pavilion", "translation": [3.5, 0, 7]}]})", "e.json"));
  const TexelGBuffer& gbuffer = session->persisted().gbuffer;
  lo.x -= 3.0f;  // the move: 3 m towards -x
  std::vector<uint32_t> near, far;
  for (uint32_t i = 0; i < gbuffer.texels.size(); ++i) {
    const Vec3& p = gbuffer.texels[i].position;
    const float dx = std::max({lo.x - p.x, 0.0f, p.x - hi.x}), dy = std::max({lo.y - p.y, 0.0f, p.y - hi.y}),
                dz = std::max({lo.z - p.z, 0.0f, p.z - hi.z});
    (dx * dx + dy * dy + dz * dz < 9.0f ? near : far).push_back(i);
  }
  EXPECT_GT(near.size(), 50u);
  EXPECT_GT(far.size(), near.size());
  CallsToError calls;
  const uint64_t budget = gbuffer.texels.size();
  for (int call = 1; call <= 200 && (calls.near == 0 || calls.far == 0); ++call) {
    session->refresh({0, 0, budget});
    const LightmapEstimate estimate = session->lightmap();
    if (!calls.near && subset_relative_mse(estimate, near) <= target) calls.near = call;
    if (!calls.far && subset_relative_mse(estimate, far) <= target) calls.far = call;
  }
  return calls;
}

TEST(RefreshSession, TexelsNearAnEditReachAnErrorInFewerCalls) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const CallsToError prioritized = calls_to_error(16), uniform = calls_to_error(0);
  std::printf("calls to the pre-edit 8-sample error: near %d, far %d (prioritized); near %d, far %d (uniform)\n",
              prioritized.near, prioritized.far, uniform.near, uniform.far);
  ASSERT_GT(prioritized.near, 0);
  ASSERT_GT(prioritized.far, 0);
  EXPECT_LT(prioritized.near, prioritized.far);
  EXPECT_LT(prioritized.near, uniform.near);  // the priorities, not the texels' own noise, make the difference
}

// set_light_subpaths: switched on before the first refresh, the session gives what one opened with
// RefreshSessionOptions::light_subpaths gives, bit for bit; switched off, its passes trace no subpath
// (the totals stop growing) and on again, they grow; a per-sample count outside (0, 64] is refused
// and changes nothing.
TEST(RefreshSession, LightSubpathsSwitchedBetweenRefreshes) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  RefreshSessionOptions with;
  with.light_subpaths = true;
  auto opened_with = RefreshSession::open(baked_bundle().string(), with);
  opened_with->refresh({0, 2});
  auto switched = RefreshSession::open(baked_bundle().string());
  EXPECT_THROW(switched->set_light_subpaths(true, 0), std::invalid_argument);
  EXPECT_THROW(switched->set_light_subpaths(true, 65), std::invalid_argument);
  EXPECT_THROW(switched->set_light_subpaths(true, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  EXPECT_FALSE(switched->settings().light_subpaths);
  switched->set_light_subpaths(true);
  EXPECT_TRUE(switched->settings().light_subpaths);
  switched->refresh({0, 2});
  const LightmapEstimate two = switched->lightmap();
  expect_same_sums(two, opened_with->lightmap());
  ASSERT_GT(two.light_subpaths, 0u);  // the Cornell room's ceiling panel starts them
  EXPECT_EQ(two.light_subpaths, opened_with->lightmap().light_subpaths);

  switched->set_light_subpaths(false);
  switched->refresh({0, 4});
  EXPECT_EQ(switched->lightmap().light_subpaths, two.light_subpaths);
  switched->set_light_subpaths(true, 0.25);
  switched->refresh({0, 5});
  const LightmapEstimate five = switched->lightmap();
  EXPECT_GT(five.light_subpaths, two.light_subpaths);
  for (const TexelAccumulator& t : five.texels) {
    ASSERT_EQ(t.samples, 5u);
    for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(t.total[c]) && t.total[c] >= 0);
  }
}

TEST(RefreshSession, BadBudgetsAreRefused) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  auto session = RefreshSession::open(baked_bundle().string());
  EXPECT_THROW(session->refresh({std::numeric_limits<double>::quiet_NaN(), 0}), std::invalid_argument);
  EXPECT_THROW(session->refresh({-1, 4}), std::invalid_argument);
  EXPECT_THROW(session->refresh({0, 0}), std::invalid_argument);
  EXPECT_EQ(session->lightmap().texels.front().samples, 0u);  // nothing was added
  EXPECT_THROW(RefreshSession::open((baked_bundle().parent_path() / "missing.bake").string()), BundleInputError);
}

}  // namespace
}  // namespace exitance
