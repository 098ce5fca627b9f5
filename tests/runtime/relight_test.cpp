// exitance-relight (runtime/src/relight) against bake: a bundle baked with the Vulkan backend (--no-skip), its
// lightmaps and probes deleted, re-lit from scene.bin with the same seed and samples gives the same
// files bit for bit (lavapipe in CI, validation layers on); a relight agrees with the CPU reference
// within statistical error; a corrupt or truncated scene.bin is one error line and exit status 2.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/formats/lightmap_exr.h"
#include "exitance/formats/scene_file.h"
#include "exitance/loader/bundle.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/refresh/refresh_session.h"
#include "exitance/runtime/relight/one_rank_alone.h"
#include "exitance/runtime/relight/relight.h"
#include "exitance/runtime/scene_file_conversion.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "support/sequential_ranks.h"
#include "support/sphere_over_floor_gltf.h"
#include "support/vulkan_device_available.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;

using testing::has_vulkan_device;

std::string file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

struct Fixture {
  fs::path dir;
  fs::path baked;
};

// Cornell room baked once on the Vulkan backend (validation on), 8 spp, probes 64 rays.
const Fixture& vulkan_bake() {
  static const Fixture fixture = [] {
    Fixture f;
    f.dir = fs::temp_directory_path() / ("exitance-relight-test-" + std::to_string(::getpid()));
    fs::remove_all(f.dir);
    fs::create_directories(f.dir);
    f.baked = f.dir / "baked.bake";
    BakeOptions options;
    options.input = std::string(EXITANCE_SAMPLE_DIR) + "/cornell_room.gltf";
    options.output = f.baked.string();
    options.backend.name = "vulkan";
    options.backend.validation = true;
    options.atlas.texel_density = 12;
    options.lighting.spp = 8;
    options.lighting.seed = 11;
    options.probe_spp = 64;
    // scene.bin holds every live texel and a relight lights them all; the bake traces the same
    // list (so the same per-texel random streams) only when it does not skip the sealed ones.
    options.skip_sealed_texels = false;
    Diagnostics diagnostics;
    run_bake(options, diagnostics);
    return f;
  }();
  return fixture;
}

TEST(Relight, ReproducesTheVulkanBakeBitForBit) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const Fixture& f = vulkan_bake();
  const fs::path input = f.dir / "stripped.bake", output = f.dir / "relit.bake";
  fs::remove_all(input);
  fs::copy(f.baked, input, fs::copy_options::recursive);
  size_t deleted = 0;
  for (const auto& entry : fs::directory_iterator(input))
    if (entry.path().extension() == ".exr" || entry.path().filename() == "probes.bin") fs::remove(entry.path()), ++deleted;
  ASSERT_GE(deleted, 2u);
  RelightOptions options;
  options.bundle = input.string();
  options.output = output.string();
  options.seed = 11;
  options.spp = 8;
  options.validation = true;
  const nlohmann::json report = relight_bundle(options);
  EXPECT_GT(report["rays"].get<uint64_t>(), 0u);
  size_t compared = 0;
  for (const auto& entry : fs::directory_iterator(f.baked)) {
    const std::string name = entry.path().filename().string();
    if (name == "manifest.json" || name == "radiance.vdb") continue;  // the manifest records the relight
    ASSERT_TRUE(fs::exists(output / name)) << name;
    EXPECT_TRUE(file_bytes(entry.path()) == file_bytes(output / name)) << name << " differs";
    ++compared;
  }
  EXPECT_GE(compared, 4u);  // lightmap page(s), probes.bin, svo.bin, scene.bin
  EXPECT_FALSE(fs::exists(output / "radiance.vdb"));
  const nlohmann::json manifest = nlohmann::json::parse(file_bytes(output / "manifest.json"));
  EXPECT_EQ(manifest["relight"]["tool"], "exitance-relight");
  EXPECT_FALSE(manifest["svo"].contains("vdb"));
  // An engine opens the re-lit bundle as it opens a baked one (the loader validates every file).
  const loader::Bundle bundle = loader::Bundle::open(output.string());
  EXPECT_EQ(bundle.pages().size(), loader::Bundle::open(f.baked.string()).pages().size());
}

// A bundle baked with --directional sh1 is relit with its nine sh1.* layers, bit for bit as the bake
// wrote them (the refresh runs the same path.h estimator over the same per-texel streams).
TEST(Relight, ReproducesADirectionalBakeBitForBit) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path dir = fs::temp_directory_path() / ("exitance-relight-directional-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path baked = dir / "directional.bake", output = dir / "directional-relit.bake";
  BakeOptions bake;
  bake.input = std::string(EXITANCE_SAMPLE_DIR) + "/cornell_room.gltf";
  bake.output = baked.string();
  bake.backend.name = "vulkan";
  bake.atlas.texel_density = 4;
  bake.lighting.spp = 4;
  bake.lighting.seed = 5;
  bake.lighting.directional = DirectionalMode::Sh1;
  bake.probes_enabled = false;
  bake.svo_enabled = false;
  bake.skip_sealed_texels = false;
  Diagnostics diagnostics;
  run_bake(bake, diagnostics);
  RelightOptions options;
  options.bundle = baked.string();
  options.output = output.string();
  options.seed = 5;
  options.spp = 4;
  relight_bundle(options);
  const nlohmann::json manifest = nlohmann::json::parse(file_bytes(output / "manifest.json"));
  EXPECT_EQ(manifest["settings"]["directional"], "sh1");
  size_t pages = 0;
  for (const auto& entry : fs::directory_iterator(baked)) {
    if (entry.path().extension() != ".exr") continue;
    const formats::LightmapImage before = formats::read_lightmap_exr(entry.path().string());
    const formats::LightmapImage after = formats::read_lightmap_exr((output / entry.path().filename()).string());
    ASSERT_TRUE(before.channels.count("sh1.y.G")) << entry.path();
    for (const auto& [name, values] : before.channels) {
      ASSERT_TRUE(after.channels.count(name)) << name;
      EXPECT_TRUE(values == after.channels.at(name)) << entry.path().filename() << " " << name << " differs";
    }
    ++pages;
  }
  EXPECT_GE(pages, 1u);
  fs::remove_all(dir);
}

// A Vulkan bake of sample `name` into `baked` for a relight to reproduce: `density` texels per metre,
// `spp`, seed 9, no probes or octree, sealed texels traced; `lighting` sets the integrator and guides.
void bake_to_relight(const char* name, const fs::path& baked, float density, uint32_t spp,
                     const std::function<void(BakeOptions&)>& lighting) {
  BakeOptions bake;
  bake.input = std::string(EXITANCE_SAMPLE_DIR) + "/" + name + ".gltf";
  bake.output = baked.string();
  bake.backend.name = "vulkan";
  lighting(bake);
  bake.atlas.texel_density = density;
  bake.lighting.spp = spp;
  bake.lighting.seed = 9;
  bake.probes_enabled = false;
  bake.svo_enabled = false;
  bake.skip_sealed_texels = false;
  Diagnostics diagnostics;
  run_bake(bake, diagnostics);
}

// Every EXR page of `baked` byte for byte the one the relight wrote into `relit`; returns how many.
size_t expect_same_pages(const fs::path& baked, const fs::path& relit, const char* whose) {
  size_t pages = 0;
  for (const auto& entry : fs::directory_iterator(baked)) {
    if (entry.path().extension() != ".exr") continue;
    EXPECT_TRUE(file_bytes(entry.path()) == file_bytes(relit / entry.path().filename()))
        << entry.path().filename() << " differs from " << whose;
    ++pages;
  }
  return pages;
}

// The per-bounce mode (--integrator bounces): a bundle baked with it on the Vulkan backend is relit
// with it from scene.bin, bit for bit (the same core loop, per-texel streams and seed); the manifest
// records the integrator; --frames is refused with it, and a directional bundle cannot use it.
TEST(Relight, ReproducesAVulkanPerBounceBakeBitForBit) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path dir = fs::temp_directory_path() / ("exitance-relight-bounces-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path baked = dir / "bounces.bake", output = dir / "bounces-relit.bake";
  bake_to_relight("cornell_room", baked, 4, 4, [](BakeOptions& b) {
    b.lighting.integrator = IntegratorMode::Bounces;
    b.integrator_auto = false;
  });
  RelightOptions options;
  options.bundle = baked.string();
  options.output = output.string();
  options.seed = 9;
  options.spp = 4;
  options.integrator = "bounces";
  const nlohmann::json report = relight_bundle(options);
  EXPECT_EQ(report["integrator"], "bounces");
  EXPECT_GT(report["rays"].get<uint64_t>(), 0u);
  const nlohmann::json manifest = nlohmann::json::parse(file_bytes(output / "manifest.json"));
  EXPECT_EQ(manifest["settings"]["integrator"], "bounces");
  EXPECT_GE(expect_same_pages(baked, output, "the per-bounce bake's"), 1u);
  // The run's layers and host seconds are reported as the bake's manifest reports them.
  const nlohmann::json& bounces = report["bounces"];
  const nlohmann::json baked_manifest = nlohmann::json::parse(file_bytes(baked / "manifest.json"));
  const nlohmann::json& baked_bounces = baked_manifest["stats"]["bounces"];
  EXPECT_EQ(bounces["samples_per_layer"], baked_bounces["samples_per_layer"]);
  EXPECT_EQ(bounces["samples_per_layer"].size(), bounces["bounces"].get<size_t>() + 1);
  EXPECT_EQ(bounces["ratio"], baked_bounces["ratio"]);
  EXPECT_GT(bounces["seconds"]["passes"].get<double>(), 0.0);
  EXPECT_GT(bounces["seconds"]["caches"].get<double>(), 0.0) << "the layers above B_0 read caches";
  // Not progressive: frames need path tracing.
  options.frames = 2;
  options.output = (dir / "refused.bake").string();
  EXPECT_THROW(relight_bundle(options), RelightInputError);
  EXPECT_FALSE(fs::exists(dir / "refused.bake"));
  fs::remove_all(dir);
}

// A bundle baked guided (`mode`: grid or auto) on the Vulkan backend at `spp` is relit with
// --guiding `mode` from scene.bin bit for bit (the same texels, grid, learning or pilot passes, choice
// and seed); the report says so; it is refused with --frames (not progressive) and with
// --integrator bounces. Returns the report and the bake's manifest.
std::pair<nlohmann::json, nlohmann::json> expect_guided_relight_bit_for_bit(const std::string& mode, GuidingMode guiding,
                                                                          uint32_t spp, float density = 4, bool whole_run = false) {
  const fs::path dir = fs::temp_directory_path() / ("exitance-relight-guided-" + mode + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path baked = dir / "guided.bake", output = dir / "guided-relit.bake";
  bake_to_relight("cornell_room", baked, density, spp, [&](BakeOptions& b) {
    b.lighting.integrator = IntegratorMode::Path;
    b.lighting.guiding = guiding;
    b.guiding_auto_given = guiding == GuidingMode::Auto;
    b.integrator_auto = false;
  });
  const nlohmann::json manifest = nlohmann::json::parse(file_bytes(baked / "manifest.json"));
  RelightOptions options;
  options.bundle = baked.string();
  options.output = output.string();
  options.seed = 9;
  options.spp = spp;
  options.guiding = mode;
  options.whole_run = whole_run;
  const nlohmann::json report = relight_bundle(options);
  EXPECT_EQ(report["integrator"], "path");
  if (whole_run) EXPECT_EQ(report["whole_run"], true);
  else EXPECT_EQ(report["guiding"], mode);
  EXPECT_GT(report["rays"].get<uint64_t>(), 0u);
  EXPECT_GE(expect_same_pages(baked, output, "the guided bake's"), 1u) << mode;
  options.output = (dir / "refused.bake").string();
  options.frames = 2;
  EXPECT_THROW(relight_bundle(options), RelightInputError);
  options.frames = 0;
  options.integrator = "bounces";
  EXPECT_THROW(relight_bundle(options), RelightInputError);
  EXPECT_FALSE(fs::exists(dir / "refused.bake"));
  fs::remove_all(dir);
  return {report, manifest};
}

// Grid guiding (--guiding grid).
TEST(Relight, ReproducesAVulkanGuidedBakeBitForBit) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  expect_guided_relight_bit_for_bit("grid", GuidingMode::Grid, 12);
}

// --guiding auto (bake --backend vulkan --guiding auto): the report's guiding_auto is the bake
// manifest's stats.guiding. At 1024 spp light subpaths are its candidate (four 256-sample pilots):
// measured and decided, the same choice. At 16 spp none fits: nothing measured, the unguided bake.
TEST(Relight, ReproducesAVulkanAutoGuidedBakeBitForBit) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const auto [report, manifest] = expect_guided_relight_bit_for_bit("auto", GuidingMode::Auto, 1024, 1.0f);
  ASSERT_TRUE(manifest["stats"].contains("guiding")) << "the bake ran no measured choice";
  ASSERT_TRUE(report.contains("guiding_auto"));
  EXPECT_EQ(report["guiding_auto"]["candidate"], "light-paths");
  EXPECT_EQ(report["guiding_auto"]["decided"], true);
  // Equal but for the setup's seconds, a time each run measures.
  nlohmann::json relit = report["guiding_auto"], baked = manifest["stats"]["guiding"];
  EXPECT_GT(relit["setup_seconds"].get<double>(), 0.0);
  relit.erase("setup_seconds");
  baked.erase("setup_seconds");
  EXPECT_EQ(relit, baked);

  const auto [short_report, short_manifest] = expect_guided_relight_bit_for_bit("auto", GuidingMode::Auto, 16);
  EXPECT_EQ(short_report["guiding_auto"], short_manifest["stats"]["guiding"]);
  EXPECT_EQ(short_report["guiding_auto"]["candidate"], "none");
  EXPECT_EQ(short_report["guiding_auto"]["decided"], false);
}

// --whole-run (what the guided runs are compared with): unguided path tracing of the whole lightmap
// in one run is the Vulkan bake's, bit for bit; refused with --frames and --integrator bounces.
TEST(Relight, WholeRunReproducesTheVulkanBakeBitForBit) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  expect_guided_relight_bit_for_bit("off", GuidingMode::Off, 12, 4, true);
}

// Emitter guiding (--emitter-guiding on): a bundle baked emitter-guided on the Vulkan backend is
// relit emitter-guided from scene.bin bit for bit (the same cache, passes, folds and seed); the
// report says what the cache held; refused with --frames (not progressive), with --guiding and an
// unknown value; after an edit that makes a material emissive, the cache is made for the edited emitters.
TEST(Relight, ReproducesAVulkanEmitterGuidedBakeBitForBit) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path dir = fs::temp_directory_path() / ("exitance-relight-emitter-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path baked = dir / "guided.bake", output = dir / "guided-relit.bake";
  bake_to_relight("building", baked, 0.5f, 12, [](BakeOptions& b) {
    b.lighting.integrator = IntegratorMode::Path;
    b.lighting.guiding = GuidingMode::Off;
    b.lighting.emitter_guiding = true;
    b.integrator_auto = false;
    b.emitter_guiding_auto = false;
  });
  RelightOptions options;
  options.bundle = baked.string();
  options.output = output.string();
  options.seed = 9;
  options.spp = 12;
  options.emitter_guiding = "on";
  const nlohmann::json report = relight_bundle(options);
  EXPECT_EQ(report["integrator"], "path");
  ASSERT_TRUE(report.contains("emitter_guiding")) << report.dump();
  EXPECT_GT(report["emitter_guiding"]["records_sampling_learned"].get<uint32_t>(), 0u);
  // The host's share is reported: a fold after each pass while the cache is active (at least the
  // first pass's), and the setup.
  EXPECT_GE(report["emitter_guiding"]["folds"].get<uint32_t>(), 1u);
  EXPECT_GT(report["emitter_guiding"]["setup_seconds"].get<double>(), 0.0);
  EXPECT_GE(expect_same_pages(baked, output, "the emitter-guided bake's"), 1u);
  options.output = (dir / "refused.bake").string();
  options.frames = 2;
  EXPECT_THROW(relight_bundle(options), RelightInputError);
  options.frames = 0;
  options.guiding = "grid";
  EXPECT_THROW(relight_bundle(options), RelightInputError);
  options.guiding = "off";
  options.emitter_guiding = "sometimes";
  EXPECT_THROW(relight_bundle(options), RelightInputError);
  EXPECT_FALSE(fs::exists(dir / "refused.bake"));
  // After an edit that makes a material emissive, the guide is made for the edited emitters (the
  // session edits its lighting scene in place, which the device and the cache both follow).
  const fs::path edits = dir / "glow.json";
  std::ofstream(edits) << R"({"edits": [{"material": "Wood", "emissiveFactor": [0.5, 0.4, 0.3]}]})";
  options.emitter_guiding = "on";
  options.edits_file = edits.string();
  options.output = (dir / "glowing.bake").string();
  const nlohmann::json glowing = relight_bundle(options);
  ASSERT_TRUE(glowing.contains("emitter_guiding")) << glowing.dump();
  EXPECT_GT(glowing["emitter_guiding"]["records_sampling_learned"].get<uint32_t>(), 0u);
  EXPECT_NE(glowing["emitter_guiding"]["patches"], report["emitter_guiding"]["patches"]) << "patches of the edited emitters";
  EXPECT_EQ(glowing["nonfinite_samples"].get<uint64_t>(), 0u);
  fs::remove_all(dir);
}

// exitance-relight --light-paths on with --spp alone is bake --backend vulkan --light-paths on (the
// same seed, the same pool per batch): the same pages bit for bit, and so with --emitter-guiding on
// beside it (the learned tables folded between passes, the pools' first hits weighed by them); it
// reports the subpaths, and refuses --guiding grid beside it and an unknown value, writing nothing.
TEST(Relight, ReproducesAVulkanLightPathsBakeBitForBit) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path dir = fs::temp_directory_path() / ("exitance-relight-light-paths-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path baked = dir / "connected.bake", output = dir / "connected-relit.bake";
  bake_to_relight("ajar_room", baked, 2.0f, 8, [](BakeOptions& b) {
    b.lighting.integrator = IntegratorMode::Path;
    b.lighting.guiding = GuidingMode::Off;
    b.lighting.light_subpaths = true;
    b.integrator_auto = false;
  });
  RelightOptions options;
  options.bundle = baked.string();
  options.output = output.string();
  options.seed = 9;
  options.spp = 8;
  options.light_paths = "on";
  const nlohmann::json report = relight_bundle(options);
  ASSERT_TRUE(report.contains("light_paths")) << report.dump();
  EXPECT_GT(report["light_paths"]["vertices"].get<uint64_t>(), 0u);
  EXPECT_GE(expect_same_pages(baked, output, "the light-path bake's"), 1u);

  const fs::path guided_bake = dir / "connected-guided.bake", guided_relit = dir / "connected-guided-relit.bake";
  bake_to_relight("ajar_room", guided_bake, 2.0f, 8, [](BakeOptions& b) {
    b.lighting.integrator = IntegratorMode::Path;
    b.lighting.guiding = GuidingMode::Off;
    b.lighting.light_subpaths = true;
    b.lighting.emitter_guiding = true;
    b.integrator_auto = false;
    b.emitter_guiding_auto = false;
  });
  options.bundle = guided_bake.string();
  options.output = guided_relit.string();
  options.emitter_guiding = "on";
  const nlohmann::json both = relight_bundle(options);
  ASSERT_TRUE(both.contains("light_paths") && both.contains("emitter_guiding")) << both.dump();
  EXPECT_GT(both["light_paths"]["vertices"].get<uint64_t>(), 0u);
  EXPECT_GE(expect_same_pages(guided_bake, guided_relit, "the emitter-guided light-path bake's"), 1u);
  EXPECT_EQ(both["nonfinite_samples"].get<uint64_t>(), 0u);

  options.output = (dir / "refused.bake").string();
  options.emitter_guiding = "off";
  options.guiding = "grid";
  EXPECT_THROW(relight_bundle(options), RelightInputError);
  options.guiding = "off";
  options.light_paths = "sometimes";
  EXPECT_THROW(relight_bundle(options), RelightInputError);
  EXPECT_FALSE(fs::exists(dir / "refused.bake"));
  fs::remove_all(dir);
}

// With --frames (or --time, --budget-ms) --light-paths on refreshes progressively, the session's
// passes connecting (RefreshSessionOptions::light_subpaths): refreshed before an edit that only scales
// the lamp panel's emission (its light layer scaled with 0 rays, every sample kept, the subpaths'
// start made again for the new power), then in frames after it; the totals come from the
// accumulation, and every sample is finite.
TEST(Relight, LightPathsRefreshInFramesAcrossAScalingEdit) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path dir = fs::temp_directory_path() / ("exitance-relight-light-path-frames-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path baked = dir / "ajar.bake";
  bake_to_relight("ajar_room", baked, 2.0f, 8, [](BakeOptions& b) {
    b.lighting.integrator = IntegratorMode::Path;
    b.lighting.guiding = GuidingMode::Off;
    b.integrator_auto = false;
  });
  const fs::path edits = dir / "dimmer.json";
  std::ofstream(edits) << R"({"edits": [{"material": "Panel", "emissiveFactor": [0.5, 0.4, 0.3]}]})";
  RelightOptions options;
  options.bundle = baked.string();
  options.output = (dir / "relit.bake").string();
  options.seed = 9;
  options.spp = 8;
  options.from_baked = false;  // nothing shown from before: the scaling edit needs no split of a baked lightmap
  options.light_paths = "on";
  options.samples_before_edits = 4;
  options.edits_file = edits.string();
  options.frames = 3;
  options.frame_budget_ms = 2000;
  const nlohmann::json report = relight_bundle(options);
  ASSERT_TRUE(report.contains("light_paths")) << report.dump();
  EXPECT_GT(report["light_paths"]["subpaths"].get<uint64_t>(), 0u);
  EXPECT_GT(report["light_paths"]["vertices"].get<uint64_t>(), 0u);
  EXPECT_TRUE(report["edits"]["scaled_light_layers"].get<bool>()) << report["edits"].dump();
  EXPECT_EQ(report["spp"].get<uint32_t>(), 8u);
  EXPECT_EQ(report["nonfinite_samples"].get<uint64_t>(), 0u);
  EXPECT_FALSE(report["frames"].empty());
  fs::remove_all(dir);
}

// A scene with smooth lightmap UV seams (a sphere with generated UVs over a floor): the bake stitches
// them, and so does the relight, from scene.bin's scene and atlas, bit for bit as the bake did; a bake
// written with --seams off is relit unstitched (the mode follows the bundle's stats.seams.mode).
TEST(Relight, StitchesSeamsAsTheBakeDid) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const fs::path dir = fs::temp_directory_path() / ("exitance-relight-seams-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  test::write_sphere_over_floor_gltf((dir / "sphere.gltf").string(), 24, 12, /*sun=*/true);
  for (const bool stitch : {true, false}) {
    SCOPED_TRACE(stitch ? "stitch" : "off");
    const fs::path baked = dir / (stitch ? "stitched.bake" : "off.bake");
    const fs::path output = dir / (stitch ? "stitched-relit.bake" : "off-relit.bake");
    BakeOptions bake;
    bake.input = (dir / "sphere.gltf").string();
    bake.output = baked.string();
    bake.sky = "0.3,0.35,0.45";
    bake.backend.name = "vulkan";
    bake.atlas.texel_density = 6;
    bake.lighting.spp = 4;
    bake.lighting.seed = 3;
    bake.probes_enabled = false;
    bake.svo_enabled = false;
    bake.skip_sealed_texels = false;
    bake.stitch_seams = stitch;
    Diagnostics diagnostics;
    const nlohmann::json baked_seams = run_bake(bake, diagnostics)["seams"];
    RelightOptions options;
    options.bundle = baked.string();
    options.output = output.string();
    options.seed = 3;
    options.spp = 4;
    const nlohmann::json seams = relight_bundle(options)["seams"];
    ASSERT_TRUE(seams.is_object());
    EXPECT_EQ(seams["mode"], stitch ? "stitch" : "off");
    EXPECT_EQ(seams["edges"], baked_seams["edges"]);
    EXPECT_GT(seams["edges"].get<size_t>(), 10u);
    if (stitch) {
      EXPECT_GT(seams["texels_adjusted"].get<size_t>(), 0u);
      EXPECT_LT(seams["discontinuity_after"].get<double>(), seams["discontinuity_before"].get<double>());
    } else {
      EXPECT_EQ(seams["texels_adjusted"], 0);
    }
    size_t pages = 0;
    for (const auto& entry : fs::directory_iterator(baked)) {
      if (entry.path().extension() != ".exr") continue;
      EXPECT_TRUE(file_bytes(entry.path()) == file_bytes(output / entry.path().filename()))
          << entry.path().filename() << " differs from the bake's";
      ++pages;
    }
    EXPECT_GE(pages, 1u);
  }
  fs::remove_all(dir);
}

// The relight's lightmap against the CPU reference on the same restored scene and G-buffer, with
// independent seeds: per region of 64 texels (Morton order) and channel, a z-test whose variance is
// twice the reference's (both run the same estimator at the same samples per texel).
TEST(Relight, AgreesWithTheCpuReference) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const Fixture& f = vulkan_bake();
  const fs::path output = f.dir / "relit-64.bake";
  RelightOptions options;
  options.bundle = f.baked.string();
  options.output = output.string();
  options.seed = 3;
  options.spp = 64;
  relight_bundle(options);

  const PersistedScene restored = restore_scene(formats::read_scene_file((f.baked / "scene.bin").string()));
  IntegratorSettings settings;
  settings.spp = 64;
  settings.seed = 4;
  const LightmapEstimate cpu = CpuReferenceIntegrator(restored.scene).bake(restored.gbuffer, settings);
  std::vector<formats::LightmapImage> pages;
  for (size_t p = 0; p < restored.gbuffer.pages.size(); ++p)
    pages.push_back(formats::read_lightmap_exr((output / ("lightmap-" + std::to_string(p) + ".exr")).string()));
  const char* channel_names[3] = {"R", "G", "B"};
  double worst = 0;
  size_t regions = 0;
  const size_t n = restored.gbuffer.texels.size(), group = 64;
  for (size_t begin = 0; begin < n; begin += group) {
    const size_t end = std::min(n, begin + group);
    for (int c = 0; c < 3; ++c) {
      double gpu_sum = 0, cpu_sum = 0, variance = 0;
      for (size_t i = begin; i < end; ++i) {
        const LiveTexel& t = restored.gbuffer.texels[i];
        const formats::LightmapImage& page = pages[t.page];
        gpu_sum += page.channels.at(channel_names[c])[size_t(t.y) * size_t(page.width) + t.x];
        cpu_sum += cpu.mean_total(i)[c];
        variance += 2.0 * cpu.variance_of_mean(i)[c];
      }
      const double diff = std::fabs(gpu_sum - cpu_sum);
      if (diff <= 1e-6 * std::fabs(cpu_sum) + 1e-9) continue;
      const double z = variance > 0 ? diff / std::sqrt(variance) : INFINITY;
      worst = std::max(worst, z);
      EXPECT_LT(z, 4.5) << "region " << begin << " channel " << c << " gpu " << gpu_sum << " cpu " << cpu_sum;
    }
    ++regions;
  }
  std::printf("[relight] %zu texels, %zu regions, worst |z| %.2f\n", n, regions, worst);
  EXPECT_GT(regions, 50u);
}

// Runs exitance-relight; returns its exit status and stderr.
// `environment`: assignments put before the command ("NAME=VALUE ").
int run_relight(const std::string& arguments, std::string& errors, const std::string& environment = "") {
  const std::string err_path = (fs::temp_directory_path() / ("relight-err-" + std::to_string(::getpid()))).string();
  const int status = std::system((environment + std::string(EXITANCE_RELIGHT) + " " + arguments + " 2> " + err_path).c_str());
  errors = file_bytes(err_path);
  fs::remove(err_path);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Relight, BadScenesAreOneLineAndExitTwo) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const Fixture& f = vulkan_bake();
  const std::string scene = file_bytes(f.baked / "scene.bin");
  struct Case {
    const char* name;
    std::string bytes;
  };
  std::string flipped = scene;
  flipped[scene.size() / 2] = char(flipped[scene.size() / 2] ^ 0x5A);
  const Case cases[] = {{"truncated", scene.substr(0, scene.size() / 3)}, {"empty", ""}, {"flipped", flipped},
                        {"header only", scene.substr(0, 64)}};
  for (const Case& c : cases) {
    const fs::path input = f.dir / "bad.bake", output = f.dir / "bad-out.bake";
    fs::remove_all(input);
    fs::remove_all(output);
    fs::copy(f.baked, input, fs::copy_options::recursive);
    std::ofstream(input / "scene.bin", std::ios::binary | std::ios::trunc) << c.bytes;
    std::string errors;
    EXPECT_EQ(run_relight(input.string() + " -o " + output.string() + " --spp 1", errors), 2) << c.name;
    EXPECT_EQ(std::count(errors.begin(), errors.end(), '\n'), 1) << c.name << ": " << errors;
    EXPECT_NE(errors.find("scene.bin"), std::string::npos) << c.name << ": " << errors;
    EXPECT_FALSE(fs::exists(output)) << c.name << ": partial output";
  }
  std::string errors;
  EXPECT_EQ(run_relight((f.dir / "no-such.bake").string(), errors), 2);
  EXPECT_NE(errors.find("manifest.json"), std::string::npos) << errors;
  EXPECT_EQ(run_relight(f.baked.string() + " --spp -3", errors), 2);
  // --guiding auto: a whole run, as bake's measured choice, refused with frames in one line.
  const fs::path guided_out = f.dir / "svo-out.bake";
  EXPECT_EQ(run_relight(f.baked.string() + " -o " + guided_out.string() + " --guiding auto --frames 2", errors), 2);
  EXPECT_EQ(std::count(errors.begin(), errors.end(), '\n'), 1) << errors;
  EXPECT_NE(errors.find("--guiding auto"), std::string::npos) << errors;
  EXPECT_FALSE(fs::exists(guided_out)) << "partial output";
  // SVO guiding: a whole run, and it needs the bundle's octree.
  EXPECT_EQ(run_relight(f.baked.string() + " -o " + guided_out.string() + " --guiding svo --frames 2", errors), 2);
  EXPECT_EQ(std::count(errors.begin(), errors.end(), '\n'), 1) << errors;
  EXPECT_NE(errors.find("--guiding svo"), std::string::npos) << errors;
  const fs::path no_octree = f.dir / "no-octree.bake";
  fs::remove_all(no_octree);
  fs::copy(f.baked, no_octree, fs::copy_options::recursive);
  fs::remove(no_octree / "svo.bin");
  nlohmann::json manifest = nlohmann::json::parse(file_bytes(no_octree / "manifest.json"));
  manifest.erase("svo");
  std::ofstream(no_octree / "manifest.json", std::ios::trunc) << manifest.dump(2);
  EXPECT_EQ(run_relight(no_octree.string() + " -o " + guided_out.string() + " --guiding svo --spp 1", errors), 2);
  EXPECT_EQ(std::count(errors.begin(), errors.end(), '\n'), 1) << errors;
  EXPECT_NE(errors.find("svo.bin"), std::string::npos) << errors;
  EXPECT_FALSE(fs::exists(guided_out)) << "partial output";
  // Light layers kept in a whole run (so the bundle holds them) and refused together with none.
  EXPECT_EQ(run_relight(f.baked.string() + " -o " + guided_out.string() + " --light-layers --no-light-layers --spp 1", errors), 2);
  EXPECT_EQ(std::count(errors.begin(), errors.end(), '\n'), 1) << errors;
  EXPECT_NE(errors.find("--light-layers and --no-light-layers"), std::string::npos) << errors;
  EXPECT_FALSE(fs::exists(guided_out)) << "partial output";
  const fs::path layered = f.dir / "layered.bake";
  ASSERT_EQ(run_relight(f.baked.string() + " -o " + layered.string() + " --light-layers --spp 2", errors), 0) << errors;
  const nlohmann::json written = nlohmann::json::parse(file_bytes(layered / "manifest.json"));
  ASSERT_TRUE(written.contains("light_layers")) << written["relight"]["bundle_light_layers"].dump();
  EXPECT_TRUE(fs::exists(layered / written["light_layers"]["files"][0].get<std::string>()));
  // --denoise filters the indirect light, which light layers do not keep apart: refused with them;
  // alone it writes the filtered pages and says so.
  EXPECT_EQ(run_relight(f.baked.string() + " -o " + guided_out.string() + " --light-layers --denoise --spp 1", errors), 2);
  EXPECT_EQ(std::count(errors.begin(), errors.end(), '\n'), 1) << errors;
  EXPECT_NE(errors.find("--denoise"), std::string::npos) << errors;
  EXPECT_FALSE(fs::exists(guided_out)) << "partial output";
  const fs::path denoised = f.dir / "denoised.bake";
  ASSERT_EQ(run_relight(f.baked.string() + " -o " + denoised.string() + " --denoise --spp 2", errors), 0) << errors;
  const nlohmann::json filtered = nlohmann::json::parse(file_bytes(denoised / "manifest.json"));
  EXPECT_GT(filtered["relight"]["denoise"]["texels"].get<uint64_t>(), 0u) << filtered["relight"].dump();
  EXPECT_FALSE(filtered.contains("light_layers"));
}

// A submission past the fence timeout (EXITANCE_VULKAN_FENCE_TIMEOUT, here 1 ms) ends the run
// with one line naming the stage, exit 3 (device failure), nothing written, and no wait for the
// device; the test's CTest TIMEOUT would catch a wait.
TEST(Relight, ADeviceTimeoutExitsThreeWritingNothing) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const Fixture& f = vulkan_bake();
  const fs::path output = f.dir / "timed-out.bake";
  fs::remove_all(output);
  std::string errors;
  EXPECT_EQ(run_relight(f.baked.string() + " -o " + output.string() + " --spp 256", errors, "EXITANCE_VULKAN_FENCE_TIMEOUT=0.001 "),
            kDeviceFailureExitCode);
  EXPECT_EQ(std::count(errors.begin(), errors.end(), '\n'), 1) << errors;
  EXPECT_NE(errors.find("exitance-relight: error: device failure during "), std::string::npos) << errors;
  EXPECT_NE(errors.find("did not finish within 0.001 s"), std::string::npos) << errors;
  EXPECT_FALSE(fs::exists(output)) << "partial output";
  EXPECT_EQ(run_relight(f.baked.string() + " -o " + output.string() + " --spp 1", errors, "EXITANCE_VULKAN_FENCE_TIMEOUT=soon "), 1);
  EXPECT_NE(errors.find("EXITANCE_VULKAN_FENCE_TIMEOUT: expected seconds > 0, got 'soon'"), std::string::npos) << errors;
  EXPECT_FALSE(fs::exists(output)) << "partial output";
}

// What relight --share R/N times: rank R's texels of a bake under mpirun, alone. Each rank's
// texels are estimated bit for bit as in the one-process run (per-texel streams); the ranks' texels
// are disjoint and cover every texel; gathered onto rank 0 they are the one-process estimate, and
// the other ranks keep no per-texel sums. The CLI takes only a well-formed share of a fixed --spp run.
TEST(Relight, EachRanksShareIsItsTexelsOfTheWholeRun) {
  if (!has_vulkan_device()) GTEST_SKIP() << "no Vulkan device";
  const Fixture& f = vulkan_bake();
  RefreshSessionOptions session_options;
  session_options.seed = 11;
  const std::unique_ptr<RefreshSession> session = RefreshSession::open(f.baked.string(), session_options);
  const LightmapEstimate whole = session->bake_path(2, 0);
  ASSERT_GT(whole.texels.size(), 2048u) << "too few texels for two ranks' blocks";
  auto same_texel = [&](const LightmapEstimate& e, size_t i) {
    if (e.texels[i].samples != whole.texels[i].samples) return false;
    for (int c = 0; c < 3; ++c)
      if (e.texels[i].total[c] != whole.texels[i].total[c] || e.texels[i].total_squared[c] != whole.texels[i].total_squared[c] ||
          e.texels[i].direct[c] != whole.texels[i].direct[c])
        return false;
    return true;
  };

  // Alone, as relight --share runs it: rank 1 keeps nothing per texel; rank 0 has its own texels
  // (the others' arrive as zeros).
  {
    OneRankAlone share(1, 2);
    const LightmapEstimate part = session->bake_path(2, 0, &share);
    EXPECT_TRUE(part.texels.empty() && part.bounces.empty()) << "only rank 0 keeps per-texel sums";
    EXPECT_GT(part.rays, 0u);
    EXPECT_GT(share.work.texel_samples, whole.texels.size() / 3 * 2);
  }
  std::vector<int> owner(whole.texels.size(), 1);
  {
    OneRankAlone share(0, 2);
    const LightmapEstimate part = session->bake_path(2, 0, &share);
    ASSERT_EQ(part.texels.size(), whole.texels.size());
    for (size_t i = 0; i < part.texels.size(); ++i) {
      if (part.texels[i].samples == 0) continue;
      owner[i] = 0;
      ASSERT_TRUE(same_texel(part, i)) << "texel " << i;
    }
  }
  const auto rank0 = std::count(owner.begin(), owner.end(), 0);
  EXPECT_GT(rank0, std::ptrdiff_t(whole.texels.size() / 3));
  EXPECT_LT(rank0, std::ptrdiff_t(whole.texels.size() * 2 / 3));

  // Both ranks, one after the other, rank 0 receiving what rank 1 sent: the whole estimate.
  testing::SequentialRanks::World world;
  {
    testing::SequentialRanks share(world, 1, 2);
    EXPECT_TRUE(session->bake_path(2, 0, &share).texels.empty());
  }
  testing::SequentialRanks share(world, 0, 2);
  const LightmapEstimate gathered = session->bake_path(2, 0, &share);
  ASSERT_EQ(gathered.texels.size(), whole.texels.size());
  for (size_t i = 0; i < whole.texels.size(); ++i) ASSERT_TRUE(same_texel(gathered, i)) << "texel " << i << " of rank " << owner[i];
  EXPECT_EQ(gathered.recorded_bounces, whole.recorded_bounces);
  EXPECT_TRUE(gathered.bounces == whole.bounces) << "bounce layers differ";

  std::string errors;
  for (const char* bad : {"--spp 1 --share 2/2", "--spp 1 --share 1/0", "--spp 1 --share x", "--spp 1 --share 0/2 --time 1",
                          "--spp 0 --share 0/2", "--share 0/2"}) {
    EXPECT_EQ(run_relight(f.baked.string() + " " + bad, errors), 2) << bad;
    EXPECT_EQ(std::count(errors.begin(), errors.end(), '\n'), 1) << bad << ": " << errors;
    EXPECT_NE(errors.find("--share"), std::string::npos) << bad << ": " << errors;
  }
  const fs::path out = f.dir / "share-out.bake";
  EXPECT_EQ(run_relight(f.baked.string() + " --spp 1 --share 1/2 -o " + out.string(), errors), 2);
  EXPECT_FALSE(fs::exists(out)) << "a share writes nothing";
}

}  // namespace
}  // namespace exitance
