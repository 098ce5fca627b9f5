// Edits through the runtime's RefreshSession against a fresh bake of the edited glTF: for each kind
// of edit (light turned and moved, light intensity and colour, emission turned on from 0, sky,
// instance moved), the session's lightmap refreshed on Vulkan (lavapipe in CI) agrees with the CPU
// reference run on the scene a fresh bake of the edited glTF wrote. Per region (instance x 8x8
// atlas texels, over the texels both G-buffers have) and channel, a z-test with the two estimates'
// variances of the mean; |z| < 4.5 everywhere (about 1 false alarm in 10^5 tests per region).
// Also: an edit drops every accumulated sample unless it only scales lights (light layers: their
// layers are scaled and every sample kept); a bad edit leaves the session as it was.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <tuple>

#include <nlohmann/json.hpp>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/formats/scene_file.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/refresh/refresh_session.h"
#include "exitance/runtime/scene_file_conversion.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "support/vulkan_device_available.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

using testing::has_vulkan_device;

fs::path test_dir() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("exitance-refresh-edits-" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

json read_json(const fs::path& path) {
  std::ifstream in(path);
  return json::parse(in);
}

// Bakes `gltf` (a sample's JSON, maybe edited) into `name`.bake with the CPU backend; only its
// scene.bin is used, so few samples. The sample's .bin buffer is copied beside it.
fs::path bake_gltf(const std::string& sample, const json& gltf, const std::string& name, const std::string& sky) {
  const fs::path dir = test_dir();
  fs::copy_file(fs::path(EXITANCE_SAMPLE_DIR) / (sample + ".bin"), dir / (sample + ".bin"),
                fs::copy_options::overwrite_existing);
  const fs::path input = dir / (name + ".gltf");
  std::ofstream(input) << gltf.dump();
  BakeOptions options;
  options.input = input.string();
  options.output = (dir / (name + ".bake")).string();
  options.backend.name = "cpu";
  options.atlas.texel_density = sample == "courtyard" || sample == "building" ? 1.0f : 5.0f;
  options.lighting.spp = 1;
  options.lighting.seed = 5;
  options.probes_enabled = false;
  options.svo_enabled = false;
  options.sky = sky;
  Diagnostics diagnostics;
  run_bake(options, diagnostics);
  return options.output;
}

json sample_json(const std::string& sample) { return read_json(fs::path(EXITANCE_SAMPLE_DIR) / (sample + ".gltf")); }

json& named(json& list, const std::string& name) {
  for (json& item : list)
    if (item.value("name", "") == name) return item;
  throw std::runtime_error("no " + name);
}

struct EditCase {
  std::string label;
  std::string sample;
  std::string sky_before, sky_after;  // bake --sky
  json edits;                         // EDITS.json
  std::function<void(json&)> edit_gltf;
  bool scales = false;                // the edits only scale lights (light layers scaled, samples kept)
};

// The z-test of the header. Returns the number of regions compared.
// `base`: for a change estimate (gpu = base + change), the estimate the change was added to: where
// both sides are black with no variance, gpu may differ from 0 by the rounding of base - base
// (a few float ulps of the base's value), not more.
size_t compare_by_region(const LightmapEstimate& gpu, const TexelGBuffer& gpu_texels, const LightmapEstimate& cpu,
                         const TexelGBuffer& cpu_texels, double& worst, const LightmapEstimate* base = nullptr) {
  std::map<std::tuple<uint32_t, uint32_t, uint32_t>, size_t> cpu_index;
  for (size_t i = 0; i < cpu_texels.texels.size(); ++i) {
    const LiveTexel& t = cpu_texels.texels[i];
    cpu_index[{t.page, t.x, t.y}] = i;
  }
  struct Region {
    double gpu_sum[3] = {0, 0, 0}, cpu_sum[3] = {0, 0, 0}, variance[3] = {0, 0, 0}, cancelled[3] = {0, 0, 0};
  };
  std::map<std::tuple<uint32_t, uint32_t, uint32_t, uint32_t>, Region> regions;
  for (size_t i = 0; i < gpu_texels.texels.size(); ++i) {
    const LiveTexel& t = gpu_texels.texels[i];
    const auto match = cpu_index.find({t.page, t.x, t.y});
    if (match == cpu_index.end()) continue;
    Region& r = regions[{t.instance, t.page, t.x / 8, t.y / 8}];
    const Vec3 g = gpu.mean_total(i), c = cpu.mean_total(match->second);
    const Vec3 gv = gpu.variance_of_mean(i), cv = cpu.variance_of_mean(match->second);
    for (int k = 0; k < 3; ++k) r.gpu_sum[k] += g[k], r.cpu_sum[k] += c[k], r.variance[k] += double(gv[k]) + cv[k];
    if (base)
      for (int k = 0; k < 3; ++k) r.cancelled[k] += std::fabs(base->mean_total(i)[k]);
  }
  for (const auto& [key, r] : regions)
    for (int k = 0; k < 3; ++k) {
      const double diff = std::fabs(r.gpu_sum[k] - r.cpu_sum[k]);
      if (r.variance[k] == 0) {
        EXPECT_LE(diff, 4 * 1.2e-7 * r.cancelled[k]) << "region of instance " << std::get<0>(key);  // both black
        continue;
      }
      const double z = diff / std::sqrt(r.variance[k]);
      worst = std::max(worst, z);
      EXPECT_LT(z, 4.5) << "instance " << std::get<0>(key) << " page " << std::get<1>(key) << " block "
                        << std::get<2>(key) << "," << std::get<3>(key) << " channel " << k << ": gpu " << r.gpu_sum[k]
                        << " cpu " << r.cpu_sum[k];
    }
  return regions.size();
}

void check_edit(const EditCase& c) {
  SCOPED_TRACE(c.label);
  json before = sample_json(c.sample);
  const fs::path base = bake_gltf(c.sample, before, c.label + "-before", c.sky_before);
  json after = before;
  c.edit_gltf(after);
  const fs::path edited = bake_gltf(c.sample, after, c.label + "-after", c.sky_after);

  // The refresh: the pre-edit bundle, edited in the session, refreshed.
  RefreshSessionOptions options;
  options.seed = 17;
  auto session = RefreshSession::open(base.string(), options);
  session->refresh({0, 8});
  const LightmapEstimate pre_edit = session->published_lightmap();
  const EditEffects effects = session->apply_edits(parse_scene_edits(c.edits.dump(), c.label + ".json"));
  // Edits that only scale lights keep the 8 samples, their light layers scaled; the others keep none.
  const bool scaled = session->last_edit_timings().scaled_light_layers;
  EXPECT_EQ(scaled, c.scales);
  for (const TexelAccumulator& t : session->lightmap().texels) ASSERT_EQ(t.samples, scaled ? 8u : 0u);
  session->refresh({0, 48});
  // Other light edits are estimated as a change from the 8 pre-edit samples; the rest from nothing.
  const LightmapEstimate gpu = session->refreshed_lightmap();
  EXPECT_EQ(session->changed_lights() > 0, !scaled && !effects.lights.empty() && !effects.sky && effects.materials.empty() &&
                                               effects.moved_instances.empty());

  // The fresh bake of the edited glTF, lit by the CPU reference from its scene.bin.
  const PersistedScene fresh = restore_scene(formats::read_scene_file((edited / "scene.bin").string()));
  IntegratorSettings settings;
  settings.spp = 48;
  settings.seed = 99;
  if (!c.sky_after.empty()) ASSERT_GT(fresh.scene.sky.constant.x, 0.0f);
  const LightmapEstimate cpu = CpuReferenceIntegrator(fresh.scene).bake(fresh.gbuffer, settings);

  double worst = 0;
  const size_t regions = compare_by_region(gpu, session->persisted().gbuffer, cpu, fresh.gbuffer, worst,
                                           session->changed_lights() > 0 ? &pre_edit : nullptr);
  std::printf("[%s] %zu texels, %zu regions, worst |z| %.2f; moved instances %zu, lights %zu, materials %zu, sky %d\n",
              c.label.c_str(), gpu.texels.size(), regions, worst, effects.moved_instances.size(), effects.lights.size(),
              effects.materials.size(), int(effects.sky));
  EXPECT_GT(regions, 30u);
}

TEST(RefreshEdits, LightTurnedEqualsAFreshBake) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  // The sun node turned: its direction changes.
  const std::array<double, 4> q{-0.25, 0.35, 0.0, 0.9027735};  // unit within 1e-7
  check_edit({"sun-turned", "courtyard", "0.3,0.4,0.5", "0.3,0.4,0.5",
              {{"edits", {{{"node", "Sun"}, {"rotation", q}}}}},
              [&](json& g) { named(g["nodes"], "Sun")["rotation"] = q; }});
}

TEST(RefreshEdits, LightIntensityAndColourEqualAFreshBake) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  check_edit({"sun-brighter", "courtyard", "0.3,0.4,0.5", "0.3,0.4,0.5",
              {{"edits", {{{"light", "Sun"}, {"intensity", 6.0}, {"color", {0.6, 0.8, 1.0}}}}}},
              [](json& g) {
                json& sun = g["extensions"]["KHR_lights_punctual"]["lights"][0];
                sun["intensity"] = 6.0;
                sun["color"] = {0.6, 0.8, 1.0};
              },
              true});
}

TEST(RefreshEdits, SkyEqualsAFreshBake) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  check_edit({"sky", "courtyard", "0.3,0.4,0.5", "0.8,0.5,0.2", {{"edits", {{{"sky", {0.8, 0.5, 0.2}}}}}},
              [](json&) {}, true});
}

TEST(RefreshEdits, EmissionTurnedOnFromZeroEqualsAFreshBake) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  // "Green" has no emission: the emitter distribution must gain its triangles.
  check_edit({"green-glows", "cornell_room", "", "",
              {{"edits", {{{"material", "Green"}, {"emissiveFactor", {0.1, 0.9, 0.2}}, {"emissiveStrength", 2.0}}}}},
              [](json& g) {
                json& green = named(g["materials"], "Green");
                green["emissiveFactor"] = {0.1, 0.9, 0.2};
                green["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] = 2.0;
                json& used = g["extensionsUsed"];
                if (std::find(used.begin(), used.end(), "KHR_materials_emissive_strength") == used.end())
                  used.push_back("KHR_materials_emissive_strength");
              }});
}

TEST(RefreshEdits, InstanceMovedEqualsAFreshBake) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  // The tall box, off the floor texels it buried (which must come back: unocclude runs again near it).
  const std::array<double, 3> moved{-0.55, 0.0, 0.2};
  check_edit({"box-moved", "cornell_room", "", "", {{"edits", {{{"node", "TallBox"}, {"translation", moved}}}}},
              [&](json& g) { named(g["nodes"], "TallBox")["translation"] = moved; }});
}

// A moved instance, an emission turned on and the sky changed in one call: the moved geometry and
// emitters are uploaded on a thread of their own while the call moves texels (refresh_session.cpp),
// the sky's records with them; the refreshed lightmap agrees with a fresh bake of the edited glTF.
TEST(RefreshEdits, AMoveWithAnEmissionAndASkyInOneCallEqualsAFreshBake) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const std::array<double, 3> moved{-0.55, 0.0, 0.2};
  check_edit({"box-moved-glow-sky", "cornell_room", "0.2,0.3,0.4", "0.5,0.4,0.3",
              {{"edits",
                {{{"node", "TallBox"}, {"translation", moved}},
                 {{"material", "Green"}, {"emissiveFactor", {0.1, 0.9, 0.2}}},
                 {{"sky", {0.5, 0.4, 0.3}}}}}},
              [&](json& g) {
                named(g["nodes"], "TallBox")["translation"] = moved;
                named(g["materials"], "Green")["emissiveFactor"] = {0.1, 0.9, 0.2};
              }});
}

// A point light moved (and brighter) in one room of the building: estimated as a change from the
// pre-edit estimate, which agrees with a fresh bake of the edited glTF, leaves every texel the light
// reaches neither before nor after at its pre-edit value exactly, and is never published with fewer
// than 2 samples of the change.
TEST(RefreshEdits, PointLightMovedIsEstimatedAsAChange) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const std::array<double, 3> moved{4.2, 2.2, 12.0};
  const EditCase c{"point-moved", "building", "", "",
                   {{"edits", {{{"node", "Room_0_0_2_Point"}, {"translation", moved}}, {{"light", "Room_0_0_2_Point"}, {"intensity", 8.0}}}}},
                   [&](json& g) {
                     json& node = named(g["nodes"], "Room_0_0_2_Point");
                     node["translation"] = moved;
                     g["extensions"]["KHR_lights_punctual"]["lights"][node["extensions"]["KHR_lights_punctual"]["light"].get<int>()]["intensity"] = 8.0;
                   }};
  check_edit(c);

  const fs::path base = test_dir() / "point-moved-before.bake";
  RefreshSessionOptions options;
  options.seed = 23;
  auto session = RefreshSession::open(base.string(), options);
  session->refresh({0, 16});
  const LightmapEstimate before = session->published_lightmap();
  session->apply_edits(parse_scene_edits(c.edits.dump(), "point-moved.json"));
  EXPECT_EQ(session->changed_lights(), 1u);
  session->refresh({0, 1});
  const LightmapEstimate one = session->published_lightmap();
  for (size_t i = 0; i < one.texels.size(); ++i) ASSERT_EQ(one.texels[i].total[0], before.texels[i].total[0]) << "texel " << i;
  session->refresh({0, 32});
  const LightmapEstimate change = session->lightmap(), published = session->published_lightmap();
  size_t untouched = 0, changed = 0;
  for (size_t i = 0; i < change.texels.size(); ++i) {
    const TexelAccumulator& d = change.texels[i];
    ASSERT_EQ(d.samples, 32u);
    const bool zero = d.total[0] == 0 && d.total[1] == 0 && d.total[2] == 0 && d.total_squared[0] == 0 &&
                      d.total_squared[1] == 0 && d.total_squared[2] == 0;
    if (!zero) {
      ++changed;
      continue;
    }
    ++untouched;
    for (int k = 0; k < 3; ++k) ASSERT_EQ(published.texels[i].total[k], before.texels[i].total[k]) << "texel " << i;
  }
  std::printf("[point-moved] %zu texels the moved light reaches neither before nor after, %zu it does\n", untouched, changed);
  // One light of 18 in one room of 48: most texels are out of its reach both before and after.
  EXPECT_GT(untouched, changed);
}

TEST(RefreshEdits, ABadEditLeavesTheSessionAsItWas) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path base = bake_gltf("cornell_room", sample_json("cornell_room"), "bad-edit", "");
  auto session = RefreshSession::open(base.string());
  session->refresh({0, 3});
  const LightmapEstimate before = session->lightmap();
  const json bad = {{"edits", {{{"node", "TallBox"}, {"translation", {1.0, 0.0, 0.0}}},
                               {{"light", "NoSuchLamp"}, {"intensity", 2.0}}}}};
  try {
    session->apply_edits(parse_scene_edits(bad.dump(), "bad.json"));
    FAIL() << "the unknown light was accepted";
  } catch (const SceneEditError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json: edits[1]"), std::string::npos) << e.what();
  }
  // Unchanged: the samples, the scene, and the next samples continue where they were.
  const LightmapEstimate after = session->lightmap();
  ASSERT_EQ(after.texels.size(), before.texels.size());
  for (size_t i = 0; i < after.texels.size(); ++i) ASSERT_EQ(after.texels[i].total[0], before.texels[i].total[0]);
  const std::vector<Vec3>& positions = session->persisted().scene.positions;
  const std::vector<Vec3> original = restore_scene(session->scene_file()).scene.positions;
  ASSERT_EQ(positions.size(), original.size());
  for (size_t i = 0; i < positions.size(); ++i)
    ASSERT_TRUE(positions[i].x == original[i].x && positions[i].y == original[i].y && positions[i].z == original[i].z);
  EXPECT_EQ(session->refresh({0, 4}).samples_added, 1u);
}

}  // namespace
}  // namespace exitance
