// Golden tests (issue 14, label golden): the view drawn from a baked bundle against a path-traced view
// of the same camera computed by the CPU reference (independent of the backend that baked; one ray
// through each pixel centre), within a tolerance derived from both images' own noise and the
// lightmap's texel size (golden_comparison.h, docs/view.md "Golden tests"). Bundles broken on purpose
// (an instance reading another instance's lightmap, a mirrored scale_offset) must fail the same test.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/view/path_traced_view.h"
#include "exitance/runtime/view/view_render.h"
#include "exitance/runtime/view/view_scene.h"
#include "golden/golden_comparison.h"
#include "sample_scenes.h"
#include "support/fresh_temp_dir.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;
using testing::GoldenComparison;

// Small enough for two cores: 8 texels per metre (12.5 cm texels on a 4 m room), 128 samples per
// texel, and a 64 x 64 view path traced at 256 samples per pixel.
constexpr float kTexelDensity = 8;
constexpr uint32_t kBakeSpp = 128;
constexpr int kImageSide = 64;
constexpr uint32_t kPathTracedSpp = 256;
// A broken bundle must miss the tolerance by this factor at least.
constexpr double kBrokenMargin = 2;

nlohmann::json read_json(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return nlohmann::json::parse(text.str());
}

class GoldenCornellRoom : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(testing::fresh_temp_dir("golden-cornell"));
    samples::SceneBuilder builder;
    samples::buildCornellRoom(builder);
    builder.write((*dir_ / "cornell_room.gltf").string());
    BakeOptions options;
    options.input = (*dir_ / "cornell_room.gltf").string();
    options.output = bundle().string();
    options.backend.name = "cpu";
    options.atlas.texel_density = kTexelDensity;
    options.lighting.spp = kBakeSpp;
    options.lighting.seed = 11;
    options.probes_enabled = false;
    options.svo_enabled = false;
    Diagnostics diagnostics;
    run_bake(options, diagnostics);

    // The reference: the CPU reference path tracer at the pixel centres (an independent seed).
    const view::ViewScene scene = view::open_view_scene(bundle().string());
    const CpuReferenceIntegrator reference(*view::lighting_scene_of(scene)->source);
    IntegratorSettings settings;
    settings.spp = kPathTracedSpp;
    settings.seed = 977;
    settings.recorded_bounces = 1;
    traced_ = new view::PathTracedView(view::render_path_traced_view(scene, camera(), kImageSide, kImageSide, reference, settings));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    delete traced_;
  }
  static fs::path bundle() { return *dir_ / "cornell_room.bake"; }
  // From inside the front wall, looking at the back wall: floor, ceiling light, both coloured walls
  // and both boxes in view.
  static view::PinholeCamera camera() { return view::look_at_camera({0, 2, 1.9f}, {0, 1.7f, -2}, {0, 1, 0}, 1.1); }

  // The golden test on the bundle in `directory` (its manifest possibly edited).
  static GoldenComparison golden(const fs::path& directory) {
    const view::ViewScene scene = view::open_view_scene(directory.string());
    view::ViewRenderOptions options;
    options.width = options.height = kImageSide;
    const view::ViewImage baked = view::render_view(scene, camera(), options);
    const double floor = read_json(directory / "manifest.json")["stats"]["error"]["floor"].get<double>();
    return testing::compare_with_path_traced(scene, camera(), baked, *traced_, floor);
  }

  // A copy of the bundle whose manifest `edit` changed.
  template <typename Edit>
  static fs::path broken_copy(const std::string& name, Edit edit) {
    const fs::path copy = *dir_ / name;
    fs::remove_all(copy);
    fs::copy(bundle(), copy, fs::copy_options::recursive);
    nlohmann::json manifest = read_json(copy / "manifest.json");
    edit(manifest);
    std::ofstream(copy / "manifest.json") << manifest.dump();
    return copy;
  }

  static nlohmann::json& instance_named(nlohmann::json& manifest, const std::string& name) {
    for (nlohmann::json& instance : manifest["instances"])
      if (instance["name"] == name) return instance;
    throw std::runtime_error("no instance " + name);
  }

  static fs::path* dir_;
  static view::PathTracedView* traced_;
};
fs::path* GoldenCornellRoom::dir_ = nullptr;
view::PathTracedView* GoldenCornellRoom::traced_ = nullptr;

TEST_F(GoldenCornellRoom, BakedViewMatchesThePathTracedReference) {
  EXPECT_EQ(traced_->estimate.nonfinite_samples, 0u);
  const GoldenComparison g = golden(bundle());
  testing::print_golden("cornell_room", g);
  EXPECT_GT(g.pixels, size_t(kImageSide * kImageSide * 9 / 10));
  EXPECT_LT(g.rel_mse, g.tolerance);
}

// The floor drawn with the back wall's lightmap (page and scale_offset swapped between the two).
TEST_F(GoldenCornellRoom, AnInstanceReadingAnotherInstancesLightmapFails) {
  const fs::path broken = broken_copy("swapped.bake", [](nlohmann::json& manifest) {
    nlohmann::json& floor = instance_named(manifest, "Floor");
    nlohmann::json& back = instance_named(manifest, "BackWall");
    std::swap(floor["page"], back["page"]);
    std::swap(floor["scale_offset"], back["scale_offset"]);
    if (floor.contains("rect") && back.contains("rect")) std::swap(floor["rect"], back["rect"]);
  });
  const GoldenComparison g = golden(broken);
  testing::print_golden("cornell_room, Floor <-> BackWall", g);
  EXPECT_GT(g.rel_mse, kBrokenMargin * g.tolerance);
}

// The back wall's lightmap mirrored top to bottom (v -> 1 - v inside its rectangle): the light comes
// from the ceiling, so the wall is not symmetric that way.
TEST_F(GoldenCornellRoom, AMirroredScaleOffsetFails) {
  const fs::path broken = broken_copy("mirrored.bake", [](nlohmann::json& manifest) {
    nlohmann::json& so = instance_named(manifest, "BackWall")["scale_offset"];
    const double sy = so[1].get<double>(), oy = so[3].get<double>();
    so[1] = -sy;
    so[3] = oy + sy;
  });
  const GoldenComparison g = golden(broken);
  testing::print_golden("cornell_room, BackWall mirrored in v", g);
  EXPECT_GT(g.rel_mse, kBrokenMargin * g.tolerance);
}

}  // namespace
}  // namespace exitance
