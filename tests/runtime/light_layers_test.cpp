// Light layers (exitance/common/light_layers.h, docs/runtime.md "Light layers") on lavapipe: the
// runtime's estimate kept per light adds up to the total, whose bits the layers leave alone; each
// layer alone agrees with a refresh of the scene lit by that light only; an edit that only scales
// lights scales their layers with 0 rays, exactly, keeps every sample and converges from there.
// The scene: the courtyard under a sun and a sky, with a point lamp added and the low wall made
// emissive, so there is a layer of every kind (sky, two punctual lights, an emissive material).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/common/light_layers.h"
#include "exitance/runtime/refresh/published_estimate.h"
#include "exitance/runtime/refresh/refresh_session.h"
#include "exitance/runtime/refresh/refreshed_bundle.h"
#include "exitance/formats/bundle_manifest.h"
#include "exitance/formats/lightmap_exr.h"
#include "exitance/runtime/bundle/light_layer_pages.h"
#include "support/lightmap_comparison.h"
#include "support/vulkan_device_available.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using testing::has_vulkan_device;

fs::path test_dir() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("exitance-light-layers-" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

json& named(json& list, const std::string& name) {
  for (json& item : list)
    if (item.value("name", "") == name) return item;
  throw std::runtime_error("no " + name);
}

// Which lights the courtyard variant keeps (the others off: 0 intensity, no emission, black sky).
struct Lit {
  bool sun = true, lamp = true, wall = true, sky = true;
};

// The courtyard with a lamp and an emissive low wall, baked (CPU; 1 sample where only scene.bin is
// used, 16 where the session starts from the baked lightmap).
fs::path courtyard_bundle(const std::string& name, Lit lit, uint32_t spp = 1,
                          const std::function<void(BakeOptions&)>& tweak = {}) {
  const fs::path dir = test_dir();
  const fs::path bundle = dir / (name + ".bake");
  if (fs::exists(bundle)) return bundle;
  fs::copy_file(fs::path(EXITANCE_SAMPLE_DIR) / "courtyard.bin", dir / "courtyard.bin", fs::copy_options::overwrite_existing);
  std::ifstream in(fs::path(EXITANCE_SAMPLE_DIR) / "courtyard.gltf");
  json g = json::parse(in);
  json& lights = g["extensions"]["KHR_lights_punctual"]["lights"];
  if (!lit.sun) lights[0]["intensity"] = 0.0;
  lights.push_back({{"name", "Lamp"}, {"type", "point"}, {"color", {1.0, 0.8, 0.6}}, {"intensity", lit.lamp ? 60.0 : 0.0}});
  g["nodes"].push_back({{"name", "Lamp"}, {"translation", {-1.5, 2.5, 0.5}},
                        {"extensions", {{"KHR_lights_punctual", {{"light", lights.size() - 1}}}}}});
  g["scenes"][g.value("scene", 0)]["nodes"].push_back(g["nodes"].size() - 1);
  if (lit.wall) named(g["materials"], "Stone")["emissiveFactor"] = {0.9, 0.5, 0.2};
  const fs::path input = dir / (name + ".gltf");
  std::ofstream(input) << g.dump();
  BakeOptions options;
  options.input = input.string();
  options.output = bundle.string();
  options.backend.name = "cpu";
  options.atlas.texel_density = 1.0f;
  options.lighting.spp = spp;
  options.lighting.seed = 5;
  options.probes_enabled = false;
  options.svo_enabled = false;
  options.sky = lit.sky ? "0.3,0.4,0.5" : "0,0,0";
  if (tweak) tweak(options);
  Diagnostics diagnostics;
  run_bake(options, diagnostics);
  return bundle;
}

// Validation layer messages of every session (each test expects none).
std::vector<std::string>& validation_messages() {
  static std::vector<std::string> messages;
  return messages;
}

RefreshSessionOptions validated_options(uint64_t seed) {
  RefreshSessionOptions options;
  options.seed = seed;
  options.device.validation = true;
  options.device.on_validation_message = [](const std::string& m) { validation_messages().push_back(m); };
  return options;
}

void expect_no_validation_messages() {
  for (const std::string& m : validation_messages()) ADD_FAILURE() << "validation: " << m;
  validation_messages().clear();
}

std::unique_ptr<RefreshSession> open_session(const fs::path& bundle, uint64_t seed, bool layers) {
  RefreshSessionOptions options = validated_options(seed);
  options.light_layers = layers;
  options.start_from_baked = false;  // nothing before the session's own samples
  return RefreshSession::open(bundle.string(), options);
}

// Layer `layer` of `e` as an estimate of its own: the mean of texel i, with `variance[i]` as the
// variance of that mean.
LightmapEstimate layer_estimate(const LightmapEstimate& e, int layer, const std::vector<Vec3>& variance) {
  LightmapEstimate out;
  out.texels.resize(e.texels.size());
  out.rays = e.rays;
  const size_t n = e.texels.size();
  for (size_t i = 0; i < n; ++i) {
    const uint32_t samples = e.texels[i].samples;
    double mean[3], v[3];
    for (int c = 0; c < 3; ++c) {
      mean[c] = samples ? e.light_sums[(size_t(layer) * n + i) * 3 + size_t(c)] / samples : 0.0;
      v[c] = variance[i][c];
    }
    set_total_sums(out.texels[i], samples, mean, v);
  }
  return out;
}

TEST(LightLayers, AddUpToTheTotalWhoseBitsTheyLeaveAlone) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path bundle = courtyard_bundle("all-lights", {});
  auto layered = open_session(bundle, 7, true);
  auto plain = open_session(bundle, 7, false);
  const LightingScene& scene = layered->lighting_scene();
  ASSERT_EQ(scene.punctual_light_layers, 2u);
  ASSERT_EQ(scene.light_layer_count, 5u);  // sky, sun, lamp, the wall, materials made emissive later
  layered->refresh({0, 6});
  plain->refresh({0, 6});
  const LightmapEstimate a = layered->lightmap(), b = plain->lightmap();
  ASSERT_EQ(a.light_layers, 5);
  EXPECT_EQ(b.light_layers, 0);
  ASSERT_EQ(a.texels.size(), b.texels.size());
  const size_t n = a.texels.size();
  size_t differing = 0, off_split = 0;
  double layer_totals[5] = {0, 0, 0, 0, 0};
  for (size_t i = 0; i < n; ++i) {
    differing += a.texels[i].samples != b.texels[i].samples;
    for (int c = 0; c < 3; ++c) {
      differing += a.texels[i].total[c] != b.texels[i].total[c] || a.texels[i].total_squared[c] != b.texels[i].total_squared[c];
      double sum = 0;
      for (int l = 0; l < 5; ++l) {
        const double v = a.light_sums[(size_t(l) * n + i) * 3 + size_t(c)];
        EXPECT_GE(v, 0.0);
        sum += v;
        layer_totals[l] += v;
      }
      // The same float contributions added in another order: float rounding of each sample's sum.
      off_split += std::fabs(sum - a.texels[i].total[c]) > 1e-5 * a.texels[i].total[c] + 1e-30;
    }
  }
  EXPECT_EQ(differing, 0u);
  EXPECT_EQ(a.bounces, b.bounces);
  EXPECT_EQ(off_split, 0u);
  for (int l = 0; l < 4; ++l) EXPECT_GT(layer_totals[l], 0.0) << "layer " << l;
  EXPECT_EQ(layer_totals[4], 0.0);  // no material was made emissive
  std::printf("[light layers] %zu texels; layer shares: sky %.3f sun %.3f lamp %.3f wall %.3f\n", n,
              layer_totals[0] / (layer_totals[0] + layer_totals[1] + layer_totals[2] + layer_totals[3]),
              layer_totals[1] / (layer_totals[0] + layer_totals[1] + layer_totals[2] + layer_totals[3]),
              layer_totals[2] / (layer_totals[0] + layer_totals[1] + layer_totals[2] + layer_totals[3]),
              layer_totals[3] / (layer_totals[0] + layer_totals[1] + layer_totals[2] + layer_totals[3]));
  expect_no_validation_messages();
}

// Each layer, from two sessions of different seeds (their difference gives its variance), against a
// session of the scene lit by that light alone: per region of 64 texels and channel, |z| < 4.
TEST(LightLayers, EachLayerEqualsTheSceneLitByItsLightAlone) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  constexpr uint32_t kSamples = 32;
  const fs::path bundle = courtyard_bundle("all-lights", {});
  auto first = open_session(bundle, 11, true);
  auto second = open_session(bundle, 12, true);
  first->refresh({0, kSamples});
  second->refresh({0, kSamples});
  const LightmapEstimate a = first->lightmap(), b = second->lightmap();
  const size_t n = a.texels.size();
  struct Alone {
    int layer;
    const char* name;
    Lit lit;
  };
  const Alone cases[] = {{int(kSkyLightLayer), "sky-alone", {false, false, false, true}},
                         {int(punctual_light_layer(0, 2)), "sun-alone", {true, false, false, false}},
                         {int(punctual_light_layer(1, 2)), "lamp-alone", {false, true, false, false}},
                         {3, "wall-alone", {false, false, true, false}}};
  for (const Alone& alone : cases) {
    SCOPED_TRACE(alone.name);
    std::vector<Vec3> variance(n);
    LightmapEstimate mean_of_two = a;  // the two seeds' layer sums added: their mean over 2 x kSamples
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        const size_t at = (size_t(alone.layer) * n + i) * 3 + size_t(c);
        const double ma = a.light_sums[at] / kSamples, mb = b.light_sums[at] / kSamples;
        variance[i][c] = float((ma - mb) * (ma - mb) / 4);  // of (ma + mb) / 2
        mean_of_two.light_sums[at] = (ma + mb) / 2 * kSamples;
      }
    const LightmapEstimate layer = layer_estimate(mean_of_two, alone.layer, variance);
    auto only = open_session(courtyard_bundle(alone.name, alone.lit), 13, false);
    only->refresh({0, kSamples});
    const LightmapEstimate reference = only->lightmap();
    ASSERT_EQ(reference.texels.size(), n);
    testing::compare_estimates(layer, reference, 64, alone.name);
  }
  expect_no_validation_messages();
}

// An edit that only scales lights: 0 rays, every sample kept, each layer times its factor exactly,
// the total by the change; then the refresh goes on from there and agrees with a session of the
// edited scene.
TEST(LightLayers, AScalingEditScalesLayersWithNoRay) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path bundle = courtyard_bundle("all-lights", {});
  auto session = open_session(bundle, 21, true);
  session->refresh({0, 8});
  const LightmapEstimate before = session->lightmap();
  const std::string edits = R"({"edits": [{"light": "Lamp", "intensity": 150.0, "color": [0.5, 0.8, 0.6]},
                                          {"light": "Sun", "intensity": 0.0},
                                          {"material": "Stone", "emissiveFactor": [0.45, 0.5, 0.1]},
                                          {"sky": [0.6, 0.4, 0.25]}]})";
  const EditEffects effects = session->apply_edits(parse_scene_edits(edits, "scaling.json"));
  EXPECT_EQ(effects.lights.size(), 2u);
  EXPECT_TRUE(session->last_edit_timings().scaled_light_layers);
  const LightmapEstimate after = session->lightmap();
  EXPECT_EQ(after.rays, before.rays);  // nothing traced
  const size_t n = before.texels.size();
  // Per layer and channel, the factor: sky, sun off, lamp (150/60 x colour change), wall.
  const double factors[5][3] = {{2.0, 1.0, 0.5},
                                {0.0, 0.0, 0.0},
                                {150.0 / 60 * 0.5 / 1.0, 150.0 / 60 * 0.8 / 0.8, 150.0 / 60 * 0.6 / 0.6},
                                {0.5, 1.0, 0.5},
                                {1.0, 1.0, 1.0}};
  size_t differing = 0;
  for (size_t i = 0; i < n; ++i) {
    ASSERT_EQ(after.texels[i].samples, 8u);
    for (int c = 0; c < 3; ++c) {
      double total = before.texels[i].total[c];
      for (int l = 0; l < 5; ++l) {
        const size_t at = (size_t(l) * n + i) * 3 + size_t(c);
        // The device multiplies by the factor as a float (the edit's ratio of floats).
        const double expected = before.light_sums[at] * double(float(factors[l][c]));
        total += expected - before.light_sums[at];
        differing += std::fabs(after.light_sums[at] - expected) > 1e-6 * expected;
      }
      EXPECT_NEAR(after.texels[i].total[c], std::max(total, 0.0), 1e-9 * before.texels[i].total[c] + 1e-12) << "texel " << i;
    }
  }
  EXPECT_EQ(differing, 0u);

  // The refresh continues from the 8 samples; 56 more agree with 64 of a session of the edited scene.
  session->refresh({0, 64});
  const LightmapEstimate refreshed = session->lightmap();
  for (const TexelAccumulator& t : refreshed.texels) ASSERT_EQ(t.samples, 64u);
  const fs::path edited = test_dir() / "edited.bake";
  {
    std::ifstream in(fs::path(EXITANCE_SAMPLE_DIR) / "courtyard.gltf");
    json g = json::parse(in);
    json& lights = g["extensions"]["KHR_lights_punctual"]["lights"];
    lights[0]["intensity"] = 0.0;
    lights.push_back({{"name", "Lamp"}, {"type", "point"}, {"color", {0.5, 0.8, 0.6}}, {"intensity", 150.0}});
    g["nodes"].push_back({{"name", "Lamp"}, {"translation", {-1.5, 2.5, 0.5}},
                          {"extensions", {{"KHR_lights_punctual", {{"light", lights.size() - 1}}}}}});
    g["scenes"][g.value("scene", 0)]["nodes"].push_back(g["nodes"].size() - 1);
    named(g["materials"], "Stone")["emissiveFactor"] = {0.45, 0.5, 0.1};
    const fs::path input = test_dir() / "edited.gltf";
    std::ofstream(input) << g.dump();
    BakeOptions options;
    options.input = input.string();
    options.output = edited.string();
    options.backend.name = "cpu";
    options.atlas.texel_density = 1.0f;
    options.lighting.spp = 1;
    options.lighting.seed = 5;
    options.probes_enabled = false;
    options.svo_enabled = false;
    options.sky = "0.6,0.4,0.25";
    Diagnostics diagnostics;
    run_bake(options, diagnostics);
  }
  auto fresh = open_session(edited, 33, false);
  fresh->refresh({0, 64});
  testing::compare_estimates(refreshed, fresh->lightmap(), 64, "scaled-then-refreshed");
  expect_no_validation_messages();
}

// A previous estimate with no split by light (the baked lightmap at open): scaled by the
// accumulation's split at each texel once the accumulation has proportional_split_samples (before,
// the edit takes the other paths); an edit that is not a scaling drops the samples as before.
TEST(LightLayers, TheBakedLightmapFollowsTheAccumulationsSplit) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path bundle = courtyard_bundle("all-lights-16spp", {}, 16);
  {
    auto young = RefreshSession::open(bundle.string(), validated_options(41));  // 256 samples needed by default
    young->refresh({0, 4});
    young->apply_edits(parse_scene_edits(R"({"edits": [{"sky": [0.9, 1.2, 1.5]}]})", "sky.json"));
    EXPECT_FALSE(young->last_edit_timings().scaled_light_layers);
    for (const TexelAccumulator& t : young->lightmap().texels) ASSERT_EQ(t.samples, 0u);  // restarted
  }
  RefreshSessionOptions options = validated_options(41);
  options.proportional_split_samples = 1;
  auto session = RefreshSession::open(bundle.string(), options);  // from the baked lightmap
  ASSERT_TRUE(session->started_from_baked());
  session->refresh({0, 1});  // one sample: every texel still shows the baked value (publishing_rule.h)
  const LightmapEstimate shown_before = session->published_lightmap();
  const LightmapEstimate accumulated = session->lightmap();
  session->apply_edits(parse_scene_edits(R"({"edits": [{"sky": [0.9, 1.2, 1.5]}]})", "sky.json"));
  EXPECT_TRUE(session->last_edit_timings().scaled_light_layers);
  const LightmapEstimate shown_after = session->published_lightmap();
  const size_t n = accumulated.texels.size();
  size_t checked = 0;
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      if (shown_before.texels[i].total[c] == accumulated.texels[i].total[c]) continue;  // shows the accumulation
      const double sky = accumulated.light_sums[i * 3 + size_t(c)], total = accumulated.texels[i].total[c];
      if (!(total > 0)) continue;
      const double ratio = (total + sky * (3.0 - 1.0)) / total;  // every sky channel x 3 (as floats: within 1e-6)
      const double expected = shown_before.texels[i].total[c] * ratio;
      EXPECT_NEAR(shown_after.texels[i].total[c], expected, 1e-6 * expected) << "texel " << i << " channel " << c;
      ++checked;
    }
  }
  EXPECT_GT(checked, 0u);
  // A light turned is not a scaling: the accumulation restarts.
  session->apply_edits(parse_scene_edits(R"({"edits": [{"node": "Lamp", "translation": [0.5, 2.5, 0.5]}]})", "move.json"));
  EXPECT_FALSE(session->last_edit_timings().scaled_light_layers);
  for (const TexelAccumulator& t : session->lightmap().texels) ASSERT_EQ(t.samples, 0u);
  expect_no_validation_messages();
}

// A moved lamp is a change estimate whose changes go to the lamp's layer alone: what it publishes
// keeps a split by light, so once it ends, a scaling edit scales what is shown exactly, with no
// accumulated sample needed.
TEST(LightLayers, AChangeEstimateKeepsTheSplit) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path bundle = courtyard_bundle("all-lights", {});
  auto session = open_session(bundle, 51, true);
  session->refresh({0, 8});
  session->apply_edits(parse_scene_edits(R"({"edits": [{"node": "Lamp", "translation": [0.5, 2.5, 0.5]}]})", "move.json"));
  ASSERT_EQ(session->changed_lights(), 1u);
  session->refresh({0, 8});
  const int lamp = int(punctual_light_layer(1, 2));
  // Layers add up to the total within float rounding of each sample's terms; a change's terms (edited
  // minus base light) cancel, so their size is the texel's value (`scale`, an estimate of it), not the sum's.
  auto check_split = [](const LightmapEstimate& e, const char* what, int only_layer, const LightmapEstimate* scale = nullptr) {
    const size_t n = e.texels.size();
    size_t off_split = 0, outside = 0;
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        double sum = 0, magnitude = std::fabs(e.texels[i].total[c]);
        if (scale && scale->texels[i].samples > 0)
          magnitude += std::fabs(scale->texels[i].total[c]) / scale->texels[i].samples * e.texels[i].samples;
        for (int l = 0; l < e.light_layers; ++l) {
          const double v = e.light_sums[(size_t(l) * n + i) * 3 + size_t(c)];
          sum += v, magnitude += std::fabs(v);
          outside += only_layer >= 0 && l != only_layer && v != 0;
        }
        if (std::fabs(sum - e.texels[i].total[c]) > 1e-5 * magnitude + 1e-30) {
          ++off_split;
          std::printf("%s: texel %zu channel %d layers %.9g total %.9g\n", what, i, c, sum, e.texels[i].total[c]);
        }
      }
    EXPECT_EQ(off_split, 0u) << what;
    EXPECT_EQ(outside, 0u) << what;
  };
  const LightmapEstimate change = session->lightmap();
  const LightmapEstimate refreshed = session->refreshed_lightmap();
  check_split(change, "the change", lamp, &refreshed);
  double lamp_change = 0;
  for (size_t i = 0; i < change.texels.size(); ++i) lamp_change += std::fabs(change.light_sums[(size_t(lamp) * change.texels.size() + i) * 3]);
  EXPECT_GT(lamp_change, 0.0);
  check_split(refreshed, "base + change", -1);

  session->restart();  // the change estimate ends: what it published is what is shown, split by light
  const LightmapEstimate shown_before = session->published_lightmap();
  check_split(shown_before, "shown", -1);
  session->apply_edits(parse_scene_edits(R"({"edits": [{"sky": [0.9, 1.2, 1.5]}]})", "sky.json"));
  EXPECT_TRUE(session->last_edit_timings().scaled_light_layers);  // no sample needed: what is shown has its split
  const LightmapEstimate shown_after = session->published_lightmap();
  const size_t n = shown_before.texels.size();
  size_t checked = 0;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      const double expected = shown_before.texels[i].total[c] + 2.0 * shown_before.light_sums[i * 3 + size_t(c)];  // sky x 3
      EXPECT_NEAR(shown_after.texels[i].total[c], expected, 1e-6 * expected + 1e-12) << "texel " << i;
      checked += expected > 0;
    }
  EXPECT_GT(checked, 0u);
  expect_no_validation_messages();
}

}  // namespace
}  // namespace exitance

namespace exitance {
namespace {

formats::BundleManifest read_manifest(const fs::path& bundle) {
  std::ifstream in(bundle / "manifest.json");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return formats::parse_bundle_manifest(text, (bundle / "manifest.json").string());
}

// A bundle written from a session with light layers holds them (docs/bundle.md "Light layers"); a
// session that opens it starts from its lightmap split by light, so a scaling edit right after
// open scales each texel's layer exactly, with no sample refreshed.
TEST(LightLayers, ABundleKeepsTheSplitForTheNextSession) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path written = test_dir() / "written-with-layers.bake";
  LightmapEstimate shown_when_written;
  uint32_t layer_count = 0;
  {
    auto session = open_session(courtyard_bundle("all-lights", {}), 61, true);
    session->refresh({0, 32});
    shown_when_written = session->published_lightmap();
    layer_count = session->lighting_scene().light_layer_count;
    const json report = write_refreshed_bundle(*session, written.string(), json::object());
    EXPECT_TRUE(report["bundle_light_layers"]["written"].get<bool>()) << report["bundle_light_layers"].dump();
  }
  const formats::BundleManifest manifest = read_manifest(written);
  ASSERT_TRUE(manifest.light_layers.has_value());
  EXPECT_EQ(manifest.light_layers->count, layer_count);
  EXPECT_EQ(manifest.light_layers->punctual, 2u);
  ASSERT_EQ(manifest.light_layers->files.size(), manifest.pages.size());

  auto session = RefreshSession::open(written.string(), validated_options(62));
  ASSERT_TRUE(session->started_from_baked());
  const LightmapEstimate opened = session->published_lightmap();
  const size_t n = opened.texels.size();
  ASSERT_EQ(opened.light_layers, int(layer_count));
  // Each layer as written (float32 means; the baked start gives every texel the same sample count).
  size_t lit = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!opened.texels[i].samples) continue;
    for (int k = 0; k < opened.light_layers; ++k)
      for (int c = 0; c < 3; ++c) {
        const size_t at = (size_t(k) * n + i) * 3 + size_t(c);
        const double was = shown_when_written.light_sums[at] / shown_when_written.texels[i].samples;
        const double now = opened.light_sums[at] / opened.texels[i].samples;
        EXPECT_NEAR(now, was, 1e-6 * std::fabs(was) + 1e-30) << "texel " << i << " layer " << k << " channel " << c;
        lit += was != 0;
      }
  }
  EXPECT_GT(lit, n);  // several layers light most texels
  session->apply_edits(parse_scene_edits(R"({"edits": [{"sky": [0.9, 1.2, 1.5]}]})", "sky.json"));
  EXPECT_TRUE(session->last_edit_timings().scaled_light_layers);  // at open, with no sample of its own
  const LightmapEstimate scaled = session->published_lightmap();
  size_t checked = 0;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      const double expected = opened.texels[i].total[c] + 2.0 * opened.light_sums[i * 3 + size_t(c)];  // sky x 3
      EXPECT_NEAR(scaled.texels[i].total[c], expected, 1e-6 * std::fabs(expected) + 1e-12) << "texel " << i;
      checked += expected > 0;
    }
  EXPECT_GT(checked, 0u);
  expect_no_validation_messages();
}

// A bundle whose layers do not fit its scene, or whose layer file is damaged, is refused with one
// line naming the file and the problem; a session that keeps no layers opens it as any other.
TEST(LightLayers, BadLayersInABundleAreRefused) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path source = test_dir() / "layers-source.bake";
  if (!fs::exists(source)) {
    auto session = open_session(courtyard_bundle("all-lights", {}), 71, true);
    session->refresh({0, 16});
    write_refreshed_bundle(*session, source.string(), json::object());
  }
  auto damaged = [&](const std::string& name, const std::function<void(const fs::path&)>& damage) {
    const fs::path copy = test_dir() / (name + ".bake");
    fs::remove_all(copy);
    fs::copy(source, copy, fs::copy_options::recursive);
    damage(copy);
    return copy;
  };
  auto expect_refused = [&](const fs::path& bundle, const std::string& needle) {
    try {
      RefreshSession::open(bundle.string(), validated_options(72));
      ADD_FAILURE() << bundle << " opened";
    } catch (const BundleInputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(needle), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  };
  const fs::path miscounted = damaged("layers-miscounted", [](const fs::path& b) {
    std::ifstream in(b / "manifest.json");
    json m = json::parse(in);
    m["light_layers"]["count"] = m["light_layers"]["count"].get<int>() + 1;
    std::ofstream(b / "manifest.json") << m.dump(2);
  });
  expect_refused(miscounted, "manifest.json: light_layers: ");
  const fs::path stray = damaged("layers-stray-channel", [](const fs::path& b) {
    formats::LightmapImage image = formats::read_lightmap_exr((b / "light-layers-0.exr").string());
    image.channels["layer1.A"] = image.channels.begin()->second;
    formats::write_lightmap_exr((b / "light-layers-0.exr").string(), image);
  });
  expect_refused(stray, "light-layers-0.exr: channel \"layer1.A\" is not a light layer");
  const fs::path partial = damaged("layers-partial", [](const fs::path& b) {
    formats::LightmapImage image = formats::read_lightmap_exr((b / "light-layers-0.exr").string());
    image.channels.erase(light_layer_channel(0, 1));
    formats::write_lightmap_exr((b / "light-layers-0.exr").string(), image);
  });
  expect_refused(partial, "light-layers-0.exr: layer 0 has 2 of its R, G, B channels");
  const fs::path nonfinite = damaged("layers-nonfinite", [](const fs::path& b) {
    formats::LightmapImage image = formats::read_lightmap_exr((b / "light-layers-0.exr").string());
    for (float& v : image.channels[light_layer_channel(0, 2)]) v = NAN;
    formats::write_lightmap_exr((b / "light-layers-0.exr").string(), image);
  });
  expect_refused(nonfinite, "light-layers-0.exr: channel \"layer0.B\" at pixel (");
  // Without light layers the session reads none of them.
  RefreshSessionOptions options = validated_options(73);
  options.light_layers = false;
  EXPECT_TRUE(RefreshSession::open(nonfinite.string(), options)->started_from_baked());
  expect_no_validation_messages();
}

// bake --light-layers on the CPU backend (Embree path tracing, the same attribution as the Vulkan
// wavefront): the layers it writes add up to the written E/pi, a session opens them as its split,
// and each agrees per 64-texel region with the Vulkan session's layer of the same light.
TEST(LightLayers, TheCpuBakeWritesLayersThatAgreeWithVulkan) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  constexpr uint32_t kSamples = 32;
  LightmapEstimate baked[2], refreshed[2];
  for (int run = 0; run < 2; ++run) {
    const fs::path bundle = courtyard_bundle("cpu-layers-" + std::to_string(run), {}, kSamples, [run](BakeOptions& o) {
      o.lighting.light_layers = true;
      o.lighting.integrator = IntegratorMode::Path;
      o.lighting.seed = 81 + uint64_t(run);
      o.stitch_seams = false;        // R, G, B as estimated, so that the layers add up to them
      o.skip_sealed_texels = false;  // every texel traced, as the session traces them
    });
    const formats::BundleManifest manifest = read_manifest(bundle);
    ASSERT_TRUE(manifest.light_layers.has_value());
    auto opened = RefreshSession::open(bundle.string(), validated_options(90 + uint64_t(run)));
    ASSERT_TRUE(opened->started_from_baked());
    baked[run] = opened->published_lightmap();
    auto session = open_session(courtyard_bundle("all-lights", {}), 85 + uint64_t(run), true);
    session->refresh({0, kSamples});
    refreshed[run] = session->lightmap();
    ASSERT_EQ(baked[run].light_layers, refreshed[run].light_layers);
  }
  const size_t n = baked[0].texels.size();
  ASSERT_EQ(refreshed[0].texels.size(), n);
  size_t split = 0;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      double sum = 0, magnitude = 0;
      int lit_by = 0;
      for (int k = 0; k < baked[0].light_layers; ++k) {
        const double v = baked[0].light_sums[(size_t(k) * n + i) * 3 + size_t(c)];
        sum += v, magnitude += std::fabs(v), lit_by += v != 0;
      }
      EXPECT_NEAR(sum, baked[0].texels[i].total[c], 1e-5 * magnitude + 1e-12) << "texel " << i << " channel " << c;
      split += lit_by >= 2;
    }
  EXPECT_GT(split, n);  // most texels' light comes from several layers
  // Per layer, the mean of two seeds with the variance their difference gives, CPU against Vulkan.
  auto layer_of_two = [n](const LightmapEstimate (&two)[2], int layer) {
    std::vector<Vec3> variance(n);
    LightmapEstimate mean = two[0];
    for (size_t i = 0; i < n; ++i) {
      const uint32_t samples = two[0].texels[i].samples;
      for (int c = 0; c < 3; ++c) {
        const size_t at = (size_t(layer) * n + i) * 3 + size_t(c);
        const double ma = samples ? two[0].light_sums[at] / samples : 0.0, mb = samples ? two[1].light_sums[at] / samples : 0.0;
        variance[i][c] = float((ma - mb) * (ma - mb) / 4);
        mean.light_sums[at] = (ma + mb) / 2 * samples;
      }
    }
    return layer_estimate(mean, layer, variance);
  };
  for (int layer = 0; layer < baked[0].light_layers; ++layer) {
    const std::string name = "cpu layer " + std::to_string(layer);
    testing::compare_estimates(layer_of_two(refreshed, layer), layer_of_two(baked, layer), 64, name.c_str());
  }
  expect_no_validation_messages();
}

// The layer files' channel names: exactly "layer<k>.R/G/B", k in decimal without leading zeros.
TEST(LightLayers, ChannelNamesAreParsedStrictly) {
  for (uint32_t k : {0u, 7u, 129u})
    for (int c = 0; c < 3; ++c) {
      const std::optional<LightLayerChannel> parsed = parse_light_layer_channel(light_layer_channel(k, c));
      ASSERT_TRUE(parsed.has_value());
      EXPECT_EQ(parsed->layer, k);
      EXPECT_EQ(parsed->channel, c);
    }
  for (const char* bad : {"layer01.R", "layer1.A", "layerX.R", "layer.R", "layer1R", "layer-1.R", "layer1234567.R", "Layer1.R",
                          "layer1.RR", "R", ""})
    EXPECT_FALSE(parse_light_layer_channel(bad).has_value()) << bad;
}

}  // namespace
}  // namespace exitance
