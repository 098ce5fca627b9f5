// End-to-end: a glTF written by the sample scene builder goes through import, layout, raster,
// lighting and the bundle writer; the EXR and manifest are read back and checked.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/bake/input_error.h"
#include "exitance/formats/lightmap_exr.h"
#include "scene_builder.h"
#include "support/fresh_temp_dir.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;
using samples::Quad;

// Two quads at different sizes: one 4x4 floor, one 1x2 raised tile, both facing up.
fs::path write_two_plane_scene(const fs::path& dir) {
  samples::SceneBuilder builder;
  samples::Material grey;
  grey.baseColor = {0.5f, 0.5f, 0.5f};
  const auto material = builder.addMaterial(grey);
  samples::MeshBuilder floor;
  floor.addQuad(Quad::axisAligned({-2, 0, -2}, {2, 0, 2}, {0, 1, 0}), material);
  builder.addMeshNode("Floor", floor);
  samples::MeshBuilder tile;
  tile.addQuad(Quad::axisAligned({10, 1, 10}, {11, 1, 12}, {0, 1, 0}), material);
  builder.addMeshNode("Tile", tile);
  const fs::path path = dir / "planes.gltf";
  builder.write(path.string());
  return path;
}

TEST(BakePipeline, PlanesUnderSkyRoundTrip) {
  const fs::path dir = testing::fresh_temp_dir("planes");
  BakeOptions options;
  options.input = write_two_plane_scene(dir).string();
  options.output = (dir / "out.bake").string();
  options.sky = "0.25,0.5,1";
  options.atlas.texel_density = 8;
  options.lighting.spp = 8;
  Diagnostics diagnostics;
  const nlohmann::json report = run_bake(options, diagnostics);
  EXPECT_GT(report["live_texels"].get<size_t>(), 100u);

  std::ifstream manifest_file(dir / "out.bake" / "manifest.json");
  const nlohmann::json manifest = nlohmann::json::parse(manifest_file);
  EXPECT_EQ(manifest["format_version"], 1);
  EXPECT_EQ(manifest["units"]["lightmap"], "irradiance_over_pi");
  ASSERT_EQ(manifest["instances"].size(), 2u);
  ASSERT_EQ(manifest["pages"].size(), 1u);
  EXPECT_EQ(manifest["input"]["sha256"].get<std::string>().size(), 64u);

  const formats::LightmapImage page =
      formats::read_lightmap_exr((dir / "out.bake" / manifest["pages"][0]["file"].get<std::string>()).string());
  EXPECT_EQ(page.width, manifest["pages"][0]["width"].get<int>());
  const auto& r = page.channels.at("R");
  const auto& b = page.channels.at("B");
  const auto& a = page.channels.at("A");
  size_t covered = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i] <= 0) continue;
    ++covered;
    // Nothing occludes an upward plane from the sky: E/pi equals the sky radiance exactly.
    ASSERT_NEAR(r[i], 0.25f, 1e-5f);
    ASSERT_NEAR(b[i], 1.0f, 1e-5f);
  }
  EXPECT_EQ(covered, report["live_texels"].get<size_t>());

  // scale_offset maps each instance's chart into its own rectangle: the centroid of its first
  // triangle's lightmap UVs lands on a covered texel inside the rectangle.
  Diagnostics import_diagnostics;
  const Scene scene = import_gltf(options.input, {}, import_diagnostics);
  ASSERT_EQ(scene.instances.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const auto& instance = manifest["instances"][i];
    const auto so = instance["scale_offset"];
    const auto rect = instance["rect"];
    const Vec2* uv = &scene.lightmap_uv[size_t(scene.instances[i].first_triangle) * 3];
    const Vec2 centroid = (uv[0] + uv[1] + uv[2]) * (1.0f / 3.0f);
    const float u = centroid.x * so[0].get<float>() + so[2].get<float>();
    const float v = centroid.y * so[1].get<float>() + so[3].get<float>();
    const int x = int(u * float(page.width)), y = int(v * float(page.height));
    EXPECT_GE(x, rect[0].get<int>());
    EXPECT_LT(x, rect[0].get<int>() + rect[2].get<int>());
    EXPECT_GE(y, rect[1].get<int>());
    EXPECT_LT(y, rect[1].get<int>() + rect[3].get<int>());
    EXPECT_GT(a[size_t(y) * size_t(page.width) + size_t(x)], 0.0f) << instance["name"];
  }
  // The floor is 4x4 units and the tile 1x2 at 8 texels/unit: their rectangles scale with area.
  const auto floor_rect = manifest["instances"][0]["rect"], tile_rect = manifest["instances"][1]["rect"];
  EXPECT_NEAR(floor_rect[2].get<double>() * floor_rect[3].get<double>() /
                  (tile_rect[2].get<double>() * tile_rect[3].get<double>()),
              8.0, 1.5);
  fs::remove_all(dir);
}

TEST(BakePipeline, BadInputLeavesEarlierBundleUntouched) {
  const fs::path dir = testing::fresh_temp_dir("atomic");
  BakeOptions options;
  options.input = write_two_plane_scene(dir).string();
  options.output = (dir / "out.bake").string();
  options.atlas.texel_density = 4;
  options.lighting.spp = 1;
  Diagnostics diagnostics;
  run_bake(options, diagnostics);
  const auto before = fs::last_write_time(dir / "out.bake" / "manifest.json");
  options.sky = "1,nan,1";
  EXPECT_THROW(run_bake(options, diagnostics), InputError);
  EXPECT_EQ(fs::last_write_time(dir / "out.bake" / "manifest.json"), before);
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find("out.bake."), std::string::npos) << "leftover " << entry.path();
  fs::remove_all(dir);
}

// Probe and voxel settings that cannot work are bad input: one error naming the option, nothing written.
TEST(BakePipeline, ImpossibleProbeOrVoxelSettingsAreInputErrors) {
  const fs::path dir = testing::fresh_temp_dir("settings");
  BakeOptions options;
  options.input = write_two_plane_scene(dir).string();
  options.output = (dir / "out.bake").string();
  options.atlas.texel_density = 4;
  options.lighting.spp = 1;
  Diagnostics diagnostics;
  options.probe_spacing = 1e-4f;  // ~1e14 probes
  try {
    run_bake(options, diagnostics);
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.element(), "--probes");
    EXPECT_NE(std::string(e.what()).find("larger spacing"), std::string::npos) << e.what();
  }
  options.probe_spacing = 0;
  options.voxel_resolution = 3;
  EXPECT_THROW(run_bake(options, diagnostics), InputError);
  EXPECT_FALSE(fs::exists(dir / "out.bake"));
  // Both products off: a lightmap-only bundle.
  options.voxel_resolution = 0;
  options.probes_enabled = false;
  options.svo_enabled = false;
  run_bake(options, diagnostics);
  EXPECT_TRUE(fs::exists(dir / "out.bake" / "manifest.json"));
  EXPECT_FALSE(fs::exists(dir / "out.bake" / "probes.bin"));
  EXPECT_FALSE(fs::exists(dir / "out.bake" / "svo.bin"));
  EXPECT_FALSE(fs::exists(dir / "out.bake" / "radiance.vdb"));
  fs::remove_all(dir);
}

TEST(BakePipeline, SameSeedSameResult) {
  const fs::path dir = testing::fresh_temp_dir("seed");
  BakeOptions options;
  options.input = write_two_plane_scene(dir).string();
  options.sky = "1,1,1";
  options.atlas.texel_density = 4;
  options.lighting.spp = 4;
  options.lighting.seed = 42;
  Diagnostics diagnostics;
  options.output = (dir / "a.bake").string();
  run_bake(options, diagnostics);
  options.output = (dir / "b.bake").string();
  run_bake(options, diagnostics);
  const auto a = formats::read_lightmap_exr((dir / "a.bake" / "lightmap-0.exr").string());
  const auto b = formats::read_lightmap_exr((dir / "b.bake" / "lightmap-0.exr").string());
  EXPECT_EQ(a.channels, b.channels);
  fs::remove_all(dir);
}

// A --time budget shorter than the lighting's first pass (one sample of every texel, and of every
// bounce layer in the per-bounce mode): the bake keeps that pass, writes the bundle, and warns with
// the time it took against the budget. The budget here (1 ms, the least the lighting gets) is far
// below what one pass over 16 k texels takes on any machine (tens of milliseconds). The CPU's
// default per-bounce mode still gives the first bounce its sample: a lightmap of direct light alone
// would be black wherever light arrives by a bounce (it was, until B_1 ran past the budget).
TEST(BakePipeline, ABudgetBelowOnePassWarnsAndStillWrites) {
  const fs::path dir = testing::fresh_temp_dir("budget");
  BakeOptions options;
  options.input = write_two_plane_scene(dir).string();
  options.output = (dir / "out.bake").string();
  options.sky = "1,1,1";
  options.atlas.texel_density = 32;
  options.lighting.spp = 0;
  options.lighting.time_budget_seconds = 1e-3;
  options.lighting.integrator = IntegratorMode::Bounces;  // the CPU's default (bake's --integrator auto)
  options.probes_enabled = false;
  options.backend.name = "cpu";
  Diagnostics diagnostics;
  const nlohmann::json report = run_bake(options, diagnostics);
  EXPECT_GT(report["live_texels"].get<size_t>(), 16000u);
  bool warned = false;
  for (const std::string& w : diagnostics.warnings) warned = warned || w.rfind("--time: the lighting took", 0) == 0;
  EXPECT_TRUE(warned);
  EXPECT_TRUE(fs::exists(dir / "out.bake" / "lightmap-0.exr"));
  std::ifstream manifest_file(dir / "out.bake" / "manifest.json");
  const nlohmann::json stats = nlohmann::json::parse(manifest_file)["stats"];
  ASSERT_EQ(stats["lighting"]["integrator"], "bounces");
  ASSERT_GE(stats["bounces"]["bounces"].get<int>(), 1);
  EXPECT_GE(stats["bounces"]["samples_per_layer"][1].get<int>(), 1);
  fs::remove_all(dir);
}

// A box standing on a floor under the sky: the floor under it is sealed. The bake skips it
// (stats.skipped, valid = 0, A kept, filled from lit neighbours, never NaN); --no-skip traces it,
// and what it gets there is exactly black (the skip changes nothing but the fill).
TEST(BakePipeline, SealedTexelsAreSkippedAndWouldBeBlack) {
  const fs::path dir = testing::fresh_temp_dir("sealed");
  samples::SceneBuilder builder;
  samples::Material grey;
  grey.baseColor = {0.5f, 0.5f, 0.5f};
  const auto material = builder.addMaterial(grey);
  samples::MeshBuilder floor;
  floor.addQuad(Quad::axisAligned({-2, 0, -2}, {2, 0, 2}, {0, 1, 0}), material);
  builder.addMeshNode("Floor", floor);
  samples::MeshBuilder box;
  box.addBox({.center = {0, 0.5f, 0}, .size = {1, 1, 1}}, material, samples::FaceDirection::Outward,
             samples::BoxFace::AllButBottom);
  builder.addMeshNode("Box", box);
  BakeOptions options;
  options.input = (dir / "box.gltf").string();
  builder.write(options.input);
  options.sky = "1,1,1";
  options.atlas.texel_density = 16;
  options.lighting.spp = 4;
  options.probes_enabled = false;
  Diagnostics diagnostics;
  options.output = (dir / "skip.bake").string();
  const nlohmann::json skip = run_bake(options, diagnostics);
  options.skip_sealed_texels = false;
  options.output = (dir / "no-skip.bake").string();
  const nlohmann::json traced = run_bake(options, diagnostics);

  const size_t sealed = skip["sealed_texels"]["found"].get<size_t>();
  EXPECT_GT(sealed, 100u);  // about 16 x 16 under the box
  EXPECT_EQ(skip["skipped"]["sealed_texels"].get<size_t>(), sealed);
  EXPECT_EQ(skip["skipped"]["sealed_instances"].get<size_t>(), 0u);
  EXPECT_GT(skip["skipped"]["sealed_lighting_seconds_saved_estimate"].get<double>(), 0.0);
  EXPECT_EQ(traced["sealed_texels"]["found"].get<size_t>(), sealed);
  EXPECT_EQ(traced["skipped"]["sealed_texels"].get<size_t>(), 0u);
  EXPECT_EQ(skip["samples_per_texel"]["min"].get<uint64_t>(), 4u);  // over traced texels

  const auto a = formats::read_lightmap_exr((dir / "skip.bake" / "lightmap-0.exr").string());
  const auto b = formats::read_lightmap_exr((dir / "no-skip.bake" / "lightmap-0.exr").string());
  ASSERT_TRUE(a.channels.count("valid"));
  ASSERT_TRUE(b.channels.count("valid"));
  EXPECT_EQ(a.channels.at("A"), b.channels.at("A"));
  for (const auto& [name, data] : a.channels)
    for (float v : data) ASSERT_TRUE(std::isfinite(v)) << name;
  size_t invalid = 0, lit_fill = 0;
  for (size_t i = 0; i < a.channels.at("A").size(); ++i) {
    if (!(a.channels.at("A")[i] > 0)) {
      EXPECT_EQ(a.channels.at("valid")[i], 0.0f);
      continue;
    }
    EXPECT_EQ(b.channels.at("valid")[i], 1.0f);
    if (a.channels.at("valid")[i] > 0) continue;
    ++invalid;
    for (const char* c : {"R", "G", "B"}) EXPECT_EQ(b.channels.at(c)[i], 0.0f) << "traced sealed texel " << i;
    lit_fill += a.channels.at("R")[i] > 0;
  }
  EXPECT_EQ(invalid, sealed);
  EXPECT_GT(lit_fill, 0u);  // filled from the lit floor around the box
  fs::remove_all(dir);
}

}  // namespace
}  // namespace exitance
