// The bundle cache (issue 12, bake/cache/): a second bake of an unchanged scene with the same
// options reuses the first bundle file for file and runs no stage after the import; a changed
// light, option or seed is a new bake; a damaged entry is warned about and rebuilt; two bakes
// storing one key at once leave one intact entry; a bake that fails to write stores nothing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <thread>

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

// A floor lit by a point light of the given intensity.
fs::path write_lit_floor(const fs::path& dir, float intensity) {
  samples::SceneBuilder builder;
  samples::Material grey;
  grey.baseColor = {0.5f, 0.5f, 0.5f};
  const auto material = builder.addMaterial(grey);
  samples::MeshBuilder floor;
  floor.addQuad(Quad::axisAligned({-1, 0, -1}, {1, 0, 1}, {0, 1, 0}), material);
  builder.addMeshNode("Floor", floor);
  samples::PointLight light;
  light.name = "Lamp";
  light.position = {0, 1, 0};
  light.intensity = intensity;
  builder.addPointLight(light);
  const fs::path path = dir / "floor.gltf";
  builder.write(path.string());
  return path;
}

std::map<std::string, std::string> file_hashes(const fs::path& folder) {
  std::map<std::string, std::string> hashes;
  for (const auto& e : fs::directory_iterator(folder)) hashes[e.path().filename().string()] = sha256_of_file(e.path().string());
  return hashes;
}

bool reused(const json& report) { return report.contains("cache") && report["cache"].value("reused", false); }

std::vector<fs::path> entries(const fs::path& cache) {
  std::vector<fs::path> found;
  if (fs::exists(cache / "v1"))
    for (const auto& e : fs::directory_iterator(cache / "v1"))
      if (e.path().filename() != "stages") found.push_back(e.path());  // the per-stage cache (stage_cache.h)
  return found;
}

TEST(BundleCache, SecondBakeReusesTheFirstFileForFile) {
  const fs::path dir = testing::fresh_temp_dir("cache-reuse");
  const fs::path input = write_lit_floor(dir, 5);
  Diagnostics first_diagnostics, second_diagnostics;
  const json first = run_bake(small_cached_bake_options(input, dir / "a.bake", dir / "cache"), first_diagnostics);
  const json second = run_bake(small_cached_bake_options(input, dir / "b.bake", dir / "cache"), second_diagnostics);
  EXPECT_FALSE(reused(first));
  EXPECT_TRUE(reused(second));
  EXPECT_EQ(first["cache"]["key"], second["cache"]["key"]);
  EXPECT_TRUE(first["seconds"].contains("lighting"));
  EXPECT_FALSE(second["seconds"].contains("lighting")) << "a reused bake runs no lighting";
  EXPECT_FALSE(second["seconds"].contains("raster"));
  EXPECT_EQ(second_diagnostics.warnings, first_diagnostics.warnings) << "the stored bake's warnings are repeated";
  auto a = file_hashes(dir / "a.bake"), b = file_hashes(dir / "b.bake");
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [name, hash] : a)
    if (name != "manifest.json") EXPECT_EQ(b[name], hash) << name;
  std::ifstream manifest(dir / "b.bake" / "manifest.json");
  EXPECT_TRUE(json::parse(manifest)["stats"]["cache"]["reused"].get<bool>());
  EXPECT_EQ(entries(dir / "cache").size(), 1u) << "one entry, no staging folders left";
  fs::remove_all(dir);
}

TEST(BundleCache, AChangedLightOptionOrSeedIsANewBake) {
  const fs::path dir = testing::fresh_temp_dir("cache-changes");
  const fs::path cache = dir / "cache";
  Diagnostics d;
  const json base = run_bake(small_cached_bake_options(write_lit_floor(dir, 5), dir / "a.bake", cache), d);
  const json light = run_bake(small_cached_bake_options(write_lit_floor(dir, 6), dir / "b.bake", cache), d);
  BakeOptions seeded = small_cached_bake_options(write_lit_floor(dir, 5), dir / "c.bake", cache);
  seeded.lighting.seed = 1;
  const json seed = run_bake(seeded, d);
  BakeOptions denser = small_cached_bake_options(write_lit_floor(dir, 5), dir / "d.bake", cache);
  denser.atlas.texel_density = 9;
  const json density = run_bake(denser, d);
  for (const json* r : {&light, &seed, &density}) {
    EXPECT_FALSE(reused(*r));
    EXPECT_NE((*r)["cache"]["key"], base["cache"]["key"]);
  }
  EXPECT_EQ(entries(cache).size(), 4u);
  fs::remove_all(dir);
}

TEST(BundleCache, DamagedEntriesAreRebuiltNeverTrusted) {
  const fs::path dir = testing::fresh_temp_dir("cache-damaged");
  const fs::path input = write_lit_floor(dir, 5), cache = dir / "cache";
  Diagnostics d;
  run_bake(small_cached_bake_options(input, dir / "a.bake", cache), d);
  ASSERT_EQ(entries(cache).size(), 1u);
  const fs::path entry = entries(cache)[0];
  // Each damage in turn: a flipped byte, a truncation, an unlisted file, a broken entry.json.
  const std::vector<std::function<void()>> damages = {
      [&] {
        std::fstream f(entry / "lightmap-0.exr", std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(100);
        f.put('\x7f');
      },
      [&] { fs::resize_file(entry / "probes.bin", fs::file_size(entry / "probes.bin") / 2); },
      [&] { std::ofstream(entry / "extra.bin") << "x"; },
      [&] { std::ofstream(entry / "entry.json") << "{\"format\": 1"; },
  };
  for (size_t k = 0; k < damages.size(); ++k) {
    SCOPED_TRACE("damage " + std::to_string(k));
    damages[k]();
    Diagnostics damaged;
    const json rebuilt = run_bake(small_cached_bake_options(input, dir / "b.bake", cache), damaged);
    EXPECT_FALSE(reused(rebuilt));
    bool warned = false;
    for (const std::string& w : damaged.warnings) warned = warned || w.find("rebuilding it") != std::string::npos;
    EXPECT_TRUE(warned);
    Diagnostics again;
    EXPECT_TRUE(reused(run_bake(small_cached_bake_options(input, dir / "c.bake", cache), again))) << "the rebuilt entry is used";
  }
  fs::remove_all(dir);
}

TEST(BundleCache, TwoBakesStoringOneKeyAtOnceLeaveOneIntactEntry) {
  const fs::path dir = testing::fresh_temp_dir("cache-concurrent");
  const fs::path input = write_lit_floor(dir, 5), cache = dir / "cache";
  json reports[2];
  std::thread threads[2];
  for (int i = 0; i < 2; ++i)
    threads[i] = std::thread([&, i] {
      Diagnostics d;
      reports[i] = run_bake(small_cached_bake_options(input, dir / ("out" + std::to_string(i)), cache), d);
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(reports[0]["cache"]["key"], reports[1]["cache"]["key"]);
  ASSERT_EQ(entries(cache).size(), 1u) << "no staging folder left behind";
  Diagnostics d;
  const json third = run_bake(small_cached_bake_options(input, dir / "out2", cache), d);
  EXPECT_TRUE(reused(third));
  EXPECT_TRUE(d.warnings.empty() || d.warnings.back().find("rebuilding") == std::string::npos);
  fs::remove_all(dir);
}

TEST(BundleCache, AFailedBakeStoresNothing) {
  const fs::path dir = testing::fresh_temp_dir("cache-failed");
  const fs::path input = write_lit_floor(dir, 5), cache = dir / "cache";
  std::ofstream(dir / "blocker") << "a file where the output's parent folder should be";
  const BakeOptions options = small_cached_bake_options(input, dir / "blocker" / "a.bake", cache);
  Diagnostics d;
  EXPECT_THROW(run_bake(options, d), std::exception);  // every stage ran; the write failed
  EXPECT_TRUE(entries(cache).empty());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace exitance
