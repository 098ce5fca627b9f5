// bake --preview (issue 14, "Pictures"): the page PNGs and the views are in the bundle's preview/
// folder, decode at the sizes the manifest gives, show a lit surface brighter than a black one where
// the scene makes that certain, and are listed by the manifest; the cache restores them; without
// --preview there is no preview folder; without scene.bin there are pages and no views.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/formats/bundle_manifest.h"
#include "exitance/formats/lightmap_exr.h"
#include "exitance/formats/scene_file.h"
#include "scene_builder.h"
#include "support/fresh_temp_dir.h"

#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#include <stb_image.h>

namespace exitance {
namespace {

namespace fs = std::filesystem;
using samples::Quad;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

struct Png {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
  int red(int x, int y) const { return rgb[(size_t(y) * size_t(width) + size_t(x)) * 3]; }
  int luminance_sum(int x, int y) const {
    const size_t i = (size_t(y) * size_t(width) + size_t(x)) * 3;
    return rgb[i] + rgb[i + 1] + rgb[i + 2];
  }
};

Png decode_png(const fs::path& path) {
  Png png;
  int channels = 0;
  stbi_uc* pixels = stbi_load(path.string().c_str(), &png.width, &png.height, &channels, 3);
  if (!pixels) {
    ADD_FAILURE() << path << " does not decode: " << stbi_failure_reason();
    return png;
  }
  png.rgb.assign(pixels, pixels + size_t(png.width) * size_t(png.height) * 3);
  stbi_image_free(pixels);
  return png;
}

// A white tile on a black floor under a sun straight down (no sky), and a white "shade" quad below
// the floor facing down: its texels see nothing lit and are lit by nothing (E/pi = 0 exactly), while
// the tile's are E/pi = 3/pi. With `camera`, a glTF camera "Top" 5 above the tile looking down, 3:2.
fs::path write_tile_scene(const fs::path& dir, bool camera) {
  samples::SceneBuilder builder;
  samples::Material black, white;
  black.baseColor = {0, 0, 0};
  white.baseColor = {0.8f, 0.8f, 0.8f};
  const auto black_id = builder.addMaterial(black), white_id = builder.addMaterial(white);
  samples::MeshBuilder floor, tile, shade;
  floor.addQuad(Quad::axisAligned({-4, 0, -4}, {4, 0, 4}, {0, 1, 0}), black_id);
  builder.addMeshNode("Floor", floor);
  tile.addQuad(Quad::axisAligned({-1, 0.01f, -1}, {1, 0.01f, 1}, {0, 1, 0}), white_id);
  builder.addMeshNode("Tile", tile);
  shade.addQuad(Quad::axisAligned({5, -2, -0.5f}, {6, -2, 0.5f}, {0, -1, 0}), white_id);
  builder.addMeshNode("Shade", shade);
  samples::DirectionalLight sun;
  sun.name = "Sun";
  sun.intensity = 3;
  builder.addDirectionalLight(sun);
  const fs::path path = dir / "tile.gltf";
  builder.write(path.string());
  if (camera) {  // the scene builder has no cameras: add one to the JSON (as tests/view does)
    nlohmann::json gltf = nlohmann::json::parse(read_text(path));
    gltf["cameras"] = {{{"name", "Top"}, {"type", "perspective"},
                        {"perspective", {{"yfov", 1.0}, {"aspectRatio", 1.5}, {"znear", 0.01}}}}};
    const double h = std::sqrt(0.5);  // -90 degrees about X: the camera's -Z looks down -Y
    gltf["nodes"].push_back({{"name", "TopNode"}, {"camera", 0}, {"translation", {0, 5, 0}}, {"rotation", {-h, 0, 0, h}}});
    gltf["scenes"][0]["nodes"].push_back(gltf["nodes"].size() - 1);
    std::ofstream(path) << gltf.dump();
  }
  return path;
}

BakeOptions small_bake(const fs::path& input, const fs::path& output) {
  BakeOptions options;
  options.input = input.string();
  options.output = output.string();
  options.backend.name = "cpu";
  options.atlas.texel_density = 4;
  options.lighting.spp = 4;
  options.probe_spp = 64;
  options.preview = true;
  options.preview_size = 96;
  return options;
}

formats::BundleManifest read_manifest(const fs::path& bundle) {
  return formats::parse_bundle_manifest(read_text(bundle / "manifest.json"), "manifest.json");
}

const formats::InstanceInfo& instance_named(const formats::BundleManifest& manifest, const std::string& name) {
  for (const formats::InstanceInfo& i : manifest.instances)
    if (i.name == name) return i;
  throw std::runtime_error("no instance " + name);
}

TEST(BakePreview, PagesAndTheCameraViewAreWrittenListedAndShowTheLight) {
  const fs::path dir = testing::fresh_temp_dir("preview-camera");
  const fs::path bundle = dir / "tile.bake";
  Diagnostics diagnostics;
  const nlohmann::json report = run_bake(small_bake(write_tile_scene(dir, true), bundle), diagnostics);
  EXPECT_GE(report["seconds"]["preview"].get<double>(), 0.0);

  const formats::BundleManifest manifest = read_manifest(bundle);
  ASSERT_TRUE(manifest.preview.has_value());
  EXPECT_GE(nlohmann::json::parse(manifest.stats_json)["seconds"]["preview"].get<double>(), 0.0);
  ASSERT_EQ(manifest.preview->pages.size(), manifest.pages.size());
  for (size_t p = 0; p < manifest.pages.size(); ++p) {
    EXPECT_EQ(manifest.preview->pages[p], "preview/lightmap-" + std::to_string(p) + ".png");
    const Png page = decode_png(bundle / manifest.preview->pages[p]);
    EXPECT_EQ(page.width, int(manifest.pages[p].width));
    EXPECT_EQ(page.height, int(manifest.pages[p].height));
  }
  // The tile's texels (E/pi = 3/pi) against the shade's (exactly 0), at their rectangles' centres.
  const auto centre_red = [&](const formats::InstanceInfo& instance) {
    const Png page = decode_png(bundle / manifest.preview->pages[instance.page]);
    const auto& r = *instance.rect;
    return page.red(int(r[0] + r[2] / 2), int(r[1] + r[3] / 2));
  };
  EXPECT_GT(centre_red(instance_named(manifest, "Tile")), 150);  // Reinhard: 0.955 -> 0.49 -> sRGB 184
  EXPECT_EQ(centre_red(instance_named(manifest, "Shade")), 0);

  ASSERT_EQ(manifest.preview->views.size(), 1u);
  const formats::PreviewViewInfo& view = manifest.preview->views[0];
  EXPECT_EQ(view.file, "preview/view-Top.png");
  EXPECT_EQ(view.camera, "Top");
  EXPECT_EQ(view.width, 96u);
  EXPECT_EQ(view.height, 64u);  // 96 / aspectRatio 1.5
  EXPECT_NEAR(view.look_from[1], 5.0f, 1e-5f);
  EXPECT_NEAR(view.look_at[1], 4.0f, 1e-5f);
  EXPECT_NEAR(view.yfov, 1.0f, 1e-6f);
  const Png image = decode_png(bundle / view.file);
  ASSERT_EQ(image.width, 96);
  ASSERT_EQ(image.height, 64);
  // The centre sees the white tile (albedo 0.8 x 3/pi); x = 8 on the middle row sees the black floor
  // 3.4 from the centre (the half-width at the floor is 5 tan(0.5) x 1.5 = 4.1).
  EXPECT_GT(image.luminance_sum(48, 32), 3 * 150);
  EXPECT_EQ(image.luminance_sum(8, 32), 0);
  fs::remove_all(dir);
}

TEST(BakePreview, WithoutCamerasAnAutomaticViewShowsLitSurfaces) {
  const fs::path dir = testing::fresh_temp_dir("preview-auto");
  const fs::path bundle = dir / "tile.bake";
  BakeOptions options = small_bake(write_tile_scene(dir, false), bundle);
  options.preview_size = 64;
  Diagnostics diagnostics;
  run_bake(options, diagnostics);
  const formats::BundleManifest manifest = read_manifest(bundle);
  ASSERT_TRUE(manifest.preview.has_value());
  ASSERT_EQ(manifest.preview->views.size(), 1u);
  const formats::PreviewViewInfo& view = manifest.preview->views[0];
  EXPECT_EQ(view.file, "preview/view-auto.png");
  EXPECT_EQ(view.camera, "");
  const Png image = decode_png(bundle / view.file);
  ASSERT_EQ(image.width, 64);
  ASSERT_EQ(image.height, 64);
  // From outside the box's corner, the lit tile is in the picture: some pixels are bright.
  size_t bright = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) bright += image.luminance_sum(x, y) > 3 * 100;
  EXPECT_GT(bright, 20u);
  fs::remove_all(dir);
}

TEST(BakePreview, WithoutThePreviewOptionThereIsNoPreviewFolder) {
  const fs::path dir = testing::fresh_temp_dir("preview-none");
  const fs::path bundle = dir / "tile.bake";
  BakeOptions options = small_bake(write_tile_scene(dir, true), bundle);
  options.preview = false;
  Diagnostics diagnostics;
  const nlohmann::json report = run_bake(options, diagnostics);
  EXPECT_FALSE(fs::exists(bundle / "preview"));
  EXPECT_FALSE(read_manifest(bundle).preview.has_value());
  EXPECT_FALSE(report["seconds"].contains("preview"));
  fs::remove_all(dir);
}

// The cache stores the whole bundle folder, preview/ included, and --preview is part of its key.
TEST(BakePreview, TheCacheRestoresThePreviewAndKeysOnIt) {
  const fs::path dir = testing::fresh_temp_dir("preview-cache");
  const fs::path input = write_tile_scene(dir, true);
  BakeOptions options = small_bake(input, dir / "first.bake");
  options.cache_directory = (dir / "cache").string();
  Diagnostics first_diagnostics;
  run_bake(options, first_diagnostics);
  options.output = (dir / "second.bake").string();
  Diagnostics second_diagnostics;
  const nlohmann::json reused = run_bake(options, second_diagnostics);
  EXPECT_TRUE(reused["cache"]["reused"].get<bool>());
  const formats::BundleManifest manifest = read_manifest(dir / "second.bake");
  ASSERT_TRUE(manifest.preview.has_value());
  for (const std::string& file : {manifest.preview->pages[0], manifest.preview->views[0].file}) {
    ASSERT_TRUE(fs::exists(dir / "second.bake" / file)) << file;
    EXPECT_EQ(read_text(dir / "second.bake" / file), read_text(dir / "first.bake" / file)) << file;
  }
  options.preview = false;
  options.output = (dir / "third.bake").string();
  Diagnostics third_diagnostics;
  const nlohmann::json without = run_bake(options, third_diagnostics);
  EXPECT_FALSE(without["cache"]["reused"].get<bool>());
  EXPECT_FALSE(fs::exists(dir / "third.bake" / "preview"));
  fs::remove_all(dir);
}

// An environment-map sky is stored by scene.bin version 2: the bundle has scene.bin, so the
// preview has its view as well as the page PNGs, and no warning about either.
TEST(BakePreview, AnEnvironmentSkyBundleHasSceneBinAndItsViews) {
  const fs::path dir = testing::fresh_temp_dir("preview-envsky");
  formats::LightmapImage sky;
  sky.width = 8;
  sky.height = 4;
  for (const char* c : {"R", "G", "B"}) sky.channels[c].assign(32, 0.5f);
  formats::write_lightmap_exr((dir / "sky.exr").string(), sky);
  BakeOptions options = small_bake(write_tile_scene(dir, true), dir / "tile.bake");
  options.sky = (dir / "sky.exr").string();
  Diagnostics diagnostics;
  run_bake(options, diagnostics);
  const formats::BundleManifest manifest = read_manifest(dir / "tile.bake");
  ASSERT_TRUE(fs::exists(dir / "tile.bake" / "scene.bin"));
  ASSERT_TRUE(manifest.scene.has_value());
  EXPECT_EQ(manifest.scene->format_version, formats::kSceneFormatVersion);
  ASSERT_TRUE(manifest.preview.has_value());
  ASSERT_EQ(manifest.preview->views.size(), 1u);
  EXPECT_TRUE(fs::exists(dir / "tile.bake" / manifest.preview->views[0].file));
  ASSERT_EQ(manifest.preview->pages.size(), manifest.pages.size());
  EXPECT_EQ(decode_png(dir / "tile.bake" / manifest.preview->pages[0]).width, int(manifest.pages[0].width));
  for (const std::string& w : diagnostics.warnings) {
    EXPECT_EQ(w.find("--preview: no views"), std::string::npos) << w;
    EXPECT_EQ(w.find("scene.bin not written"), std::string::npos) << w;
  }
  fs::remove_all(dir);
}

// A preview that cannot be written (here a view of width 0, which the command line refuses and the
// preview writer throws for) fails the bake through the bundle writer's path: the earlier bundle at OUT stays
// as it was and no staging folder is left.
TEST(BakePreview, APreviewThatCannotBeWrittenLeavesTheEarlierBundle) {
  const fs::path dir = testing::fresh_temp_dir("preview-fail");
  const fs::path bundle = dir / "tile.bake";
  BakeOptions options = small_bake(write_tile_scene(dir, true), bundle);
  options.preview = false;
  Diagnostics first;
  run_bake(options, first);
  const std::string manifest = read_text(bundle / "manifest.json");
  options.preview = true;
  options.preview_size = 0;
  options.lighting.seed = 1;  // a different bundle, had it been written
  Diagnostics second;
  EXPECT_ANY_THROW(run_bake(options, second));
  EXPECT_EQ(read_text(bundle / "manifest.json"), manifest);
  EXPECT_FALSE(fs::exists(bundle / "preview"));
  for (const fs::directory_entry& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find("tile.bake.tmp"), std::string::npos) << e.path();
  fs::remove_all(dir);
}

int run(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// --preview-size out of 16..4096: exit 2, one line naming the option, nothing written.
TEST(BakePreview, APreviewSizeOutOfRangeIsOneLineAndExit2) {
  const fs::path dir = testing::fresh_temp_dir("preview-size");
  const std::string input = write_tile_scene(dir, false).string();
  for (const char* size : {"8", "5000", "-3", "abc", "64px"}) {
    SCOPED_TRACE(size);
    const fs::path err = dir / "stderr.txt";
    EXPECT_EQ(run(std::string(EXITANCE_BAKE) + " " + input + " --no-cache --preview-size " + size + " -o " +
                  (dir / "out.bake").string() + " 2>" + err.string()),
              2);
    const std::string message = read_text(err);
    EXPECT_EQ(message, std::string("bake: error: --preview-size ") + size + ": expected 16..4096 pixels\n");
    EXPECT_FALSE(fs::exists(dir / "out.bake"));
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace exitance
