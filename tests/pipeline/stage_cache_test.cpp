// The per-stage cache (issue 12, "Skip"; bake/cache/stage_cache.h): a bake whose light changed
// reuses every offline stage and writes the same bundle as a bake without the cache; a moved mesh
// computes the geometry stages again; a damaged stage entry is warned about, removed and computed
// again, never trusted.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>

#include <nlohmann/json.hpp>

#include "exitance/bake/cache/sha256_stream.h"
#include "exitance/bake/command/bake_pipeline.h"
#include "scene_builder.h"
#include "support/fresh_temp_dir.h"
#include "support/small_cached_bake_options.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using samples::Quad;

const std::vector<std::string> kOfflineStages = {"layout", "gbuffer", "checks", "sealed_texels", "voxelize",
                                                 "probe_placement"};

struct Edit {
  float intensity = 5;
  samples::Vec3 light_position{0.3f, 1.5f, 0.2f};
  samples::Vec3 box_position{0, 0, 0};
  float emissive_strength = 2;
};

// A floor, a closed box standing on it (its bottom is sealed), a small emissive panel and a point
// light, written to dir/scene.gltf (the same path each time: an edited scene).
fs::path write_scene(const fs::path& dir, const Edit& edit) {
  samples::SceneBuilder builder;
  samples::Material grey;
  grey.baseColor = {0.5f, 0.5f, 0.5f};
  const auto grey_id = builder.addMaterial(grey);
  samples::Material glow;
  glow.baseColor = {0.2f, 0.2f, 0.2f};
  glow.emissiveColor = {1.0f, 0.8f, 0.6f};
  glow.emissiveStrength = edit.emissive_strength;
  const auto glow_id = builder.addMaterial(glow);
  samples::MeshBuilder floor;
  floor.addQuad(Quad::axisAligned({-2, 0, -2}, {2, 0, 2}, {0, 1, 0}), grey_id);
  builder.addMeshNode("Floor", floor);
  samples::MeshBuilder box;
  box.addBox({{0, 0.25f, 0}, {0.5f, 0.5f, 0.5f}}, grey_id, samples::FaceDirection::Outward);
  builder.addMeshNode("Box", box, edit.box_position);
  samples::MeshBuilder panel;
  panel.addQuad(Quad::axisAligned({1.2f, 0.5f, -0.3f}, {1.2f, 1.0f, 0.3f}, {-1, 0, 0}), glow_id);
  builder.addMeshNode("Panel", panel);
  samples::PointLight light;
  light.name = "Lamp";
  light.position = edit.light_position;
  light.intensity = edit.intensity;
  builder.addPointLight(light);
  const fs::path path = dir / "scene.gltf";
  builder.write(path.string());
  return path;
}

// OpenVDB stamps every file with a random UUID (36 characters after the 21-byte start of the
// header): two writes of one grid differ there and only there.
constexpr size_t kVdbUuidOffset = 21, kVdbUuidSize = 36;

std::string hash_without_vdb_uuid(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes(std::istreambuf_iterator<char>(in), {});
  if (bytes.size() >= kVdbUuidOffset + kVdbUuidSize) bytes.replace(kVdbUuidOffset, kVdbUuidSize, kVdbUuidSize, '-');
  Sha256Stream h;
  h.bytes(bytes.data(), bytes.size());
  return h.hex();
}

// Every bundle file but the manifest (its stats hold run times), by SHA-256.
std::map<std::string, std::string> file_hashes(const fs::path& folder) {
  std::map<std::string, std::string> hashes;
  for (const auto& e : fs::directory_iterator(folder)) {
    const std::string name = e.path().filename().string();
    if (name == "manifest.json") continue;
    hashes[name] = name == "radiance.vdb" ? hash_without_vdb_uuid(e.path()) : sha256_of_file(e.path().string());
  }
  return hashes;
}

// The bundle an uncached bake of the same scene writes.
void expect_same_as_uncached(const fs::path& input, const fs::path& dir, const fs::path& cached_bundle,
                             const Diagnostics& cached_diagnostics) {
  BakeOptions plain = small_cached_bake_options(input, dir / "uncached.bake", "");
  Diagnostics d;
  run_bake(plain, d);
  const auto cached = file_hashes(cached_bundle), uncached = file_hashes(dir / "uncached.bake");
  EXPECT_EQ(cached.size(), uncached.size());
  EXPECT_TRUE(cached.count("lightmap-0.exr") && cached.count("probes.bin") && cached.count("svo.bin"));
  for (const auto& [name, hash] : uncached) EXPECT_EQ(cached.at(name), hash) << name << " differs from the uncached bake";
  std::vector<std::string> cached_warnings;  // the cache's own warnings aside
  for (const std::string& w : cached_diagnostics.warnings)
    if (w.rfind("cache ", 0) != 0) cached_warnings.push_back(w);
  EXPECT_EQ(cached_warnings, d.warnings);
  fs::remove_all(dir / "uncached.bake");
}

json stage_outcomes(const json& report) { return report.at("cache").at("stages"); }

fs::path stage_entry(const fs::path& cache, const std::string& stage) {
  for (const auto& e : fs::directory_iterator(cache / "v1" / "stages" / stage)) return e.path();
  return {};
}

TEST(StageCache, AnEditedLightReusesEveryOfflineStageAndBakesWhatAnUncachedBakeDoes) {
  const fs::path dir = testing::fresh_temp_dir("stage-cache-light");
  const fs::path cache = dir / "cache";
  Diagnostics first_d;
  const json first = run_bake(small_cached_bake_options(write_scene(dir, {}), dir / "a.bake", cache), first_d);
  for (const std::string& stage : kOfflineStages) EXPECT_EQ(stage_outcomes(first)[stage], "computed") << stage;
  EXPECT_GT(first["sealed_texels"]["found"].get<size_t>(), 0u) << "the scene should have sealed texels to cache";

  // Light intensity, emission strength: lighting-only edits.
  Edit brighter;
  brighter.intensity = 9;
  brighter.emissive_strength = 3;
  const fs::path input = write_scene(dir, brighter);
  Diagnostics second_d;
  const json second = run_bake(small_cached_bake_options(input, dir / "b.bake", cache), second_d);
  EXPECT_FALSE(second["cache"]["reused"].get<bool>()) << "not the same bake: the whole bundle is not reused";
  for (const std::string& stage : kOfflineStages) EXPECT_EQ(stage_outcomes(second)[stage], "reused") << stage;
  std::ifstream manifest(dir / "b.bake" / "manifest.json");
  EXPECT_EQ(json::parse(manifest)["stats"]["cache"]["stages"], stage_outcomes(second)) << "the manifest says so too";
  EXPECT_NE(file_hashes(dir / "a.bake")["lightmap-0.exr"], file_hashes(dir / "b.bake")["lightmap-0.exr"]);
  expect_same_as_uncached(input, dir, dir / "b.bake", second_d);

  // A moved light: what traces towards lights (checks, sealed texels) runs again, nothing else.
  Edit moved_light = brighter;
  moved_light.light_position = {-0.5f, 1.2f, 0.4f};
  const fs::path moved_input = write_scene(dir, moved_light);
  Diagnostics third_d;
  const json third = run_bake(small_cached_bake_options(moved_input, dir / "c.bake", cache), third_d);
  for (const std::string& stage : kOfflineStages) {
    const bool traces_to_lights = stage == "checks" || stage == "sealed_texels";
    EXPECT_EQ(stage_outcomes(third)[stage], traces_to_lights ? "computed" : "reused") << stage;
  }
  expect_same_as_uncached(moved_input, dir, dir / "c.bake", third_d);
  fs::remove_all(dir);
}

TEST(StageCache, AMovedMeshComputesTheGeometryStagesAgain) {
  const fs::path dir = testing::fresh_temp_dir("stage-cache-mesh");
  const fs::path cache = dir / "cache";
  Diagnostics d;
  run_bake(small_cached_bake_options(write_scene(dir, {}), dir / "a.bake", cache), d);
  Edit moved;
  moved.box_position = {0.6f, 0, -0.4f};
  const fs::path input = write_scene(dir, moved);
  Diagnostics moved_d;
  const json report = run_bake(small_cached_bake_options(input, dir / "b.bake", cache), moved_d);
  for (const std::string& stage : kOfflineStages) EXPECT_EQ(stage_outcomes(report)[stage], "computed") << stage;
  expect_same_as_uncached(input, dir, dir / "b.bake", moved_d);
  fs::remove_all(dir);
}

TEST(StageCache, DamagedStageEntriesAreComputedAgainWithAWarning) {
  const fs::path dir = testing::fresh_temp_dir("stage-cache-damaged");
  const fs::path cache = dir / "cache";
  Diagnostics d;
  run_bake(small_cached_bake_options(write_scene(dir, {}), dir / "a.bake", cache), d);
  // Each damage to one stage's entry, then a bake of an edited light (so the bundle cache misses).
  struct Damage {
    std::string stage;
    std::function<void(const fs::path&)> apply;
  };
  const std::vector<Damage> damages = {
      {"gbuffer",
       [](const fs::path& e) {
         std::fstream f(e / "texels.bin", std::ios::in | std::ios::out | std::ios::binary);
         f.seekp(40);
         f.put('\x7f');
       }},
      {"voxelize", [](const fs::path& e) { fs::resize_file(e / "svo.bin", fs::file_size(e / "svo.bin") / 2); }},
      {"probe_placement", [](const fs::path& e) { std::ofstream(e / "extra.bin") << "x"; }},
      {"sealed_texels", [](const fs::path& e) { std::ofstream(e / "entry.json") << "{\"format\": 1"; }},
      {"layout", [](const fs::path& e) { fs::remove(e / "layout.json"); }},
      {"checks",  // a foreign entry: entry.json written for another key
       [](const fs::path& e) {
         std::ifstream in(e / "entry.json");
         json entry = json::parse(in);
         in.close();
         entry["key"] = std::string(64, '0');
         std::ofstream(e / "entry.json") << entry.dump();
       }},
  };
  float intensity = 6;
  for (const Damage& damage : damages) {
    SCOPED_TRACE(damage.stage);
    damage.apply(stage_entry(cache, damage.stage));
    Edit edit;
    edit.intensity = intensity++;
    const fs::path input = write_scene(dir, edit);
    Diagnostics damaged;
    const json report = run_bake(small_cached_bake_options(input, dir / "b.bake", cache), damaged);
    bool warned = false;
    for (const std::string& w : damaged.warnings)
      warned = warned || (w.find("computing the " + damage.stage + " stage again") != std::string::npos);
    EXPECT_TRUE(warned);
    EXPECT_EQ(stage_outcomes(report)[damage.stage], "computed");
    expect_same_as_uncached(input, dir, dir / "b.bake", damaged);
    Diagnostics again;
    edit.intensity = intensity++;
    const json next = run_bake(small_cached_bake_options(write_scene(dir, edit), dir / "c.bake", cache), again);
    EXPECT_EQ(stage_outcomes(next)[damage.stage], "reused") << "the recomputed entry is stored again";
  }
  fs::remove_all(dir);
}

TEST(StageCache, ABundleCopiedWholeFromTheCacheSaysEveryStageWasReused) {
  const fs::path dir = testing::fresh_temp_dir("stage-cache-whole");
  const fs::path input = write_scene(dir, {});
  Diagnostics d;
  run_bake(small_cached_bake_options(input, dir / "a.bake", dir / "cache"), d);
  const json again = run_bake(small_cached_bake_options(input, dir / "b.bake", dir / "cache"), d);
  EXPECT_TRUE(again["cache"]["reused"].get<bool>());
  for (const std::string& stage : kOfflineStages) EXPECT_EQ(stage_outcomes(again)[stage], "reused") << stage;
  fs::remove_all(dir);
}

TEST(StageCache, WithoutTheCacheTheManifestHasNoStageOutcomes) {
  const fs::path dir = testing::fresh_temp_dir("stage-cache-none");
  Diagnostics d;
  const json report = run_bake(small_cached_bake_options(write_scene(dir, {}), dir / "a.bake", ""), d);
  EXPECT_FALSE(report.contains("cache"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace exitance
