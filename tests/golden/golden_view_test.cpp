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
#include <stdexcept>
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

// A sample scene baked small (CPU reference, no probes, no SVO) and its view path traced by the CPU
// reference at the pixel centres, with a seed independent of the bake's.
struct GoldenScene {
  fs::path dir, bundle;
  view::PinholeCamera camera;
  view::PathTracedView traced;
};

template <typename Build>
GoldenScene bake_and_trace(const std::string& name, Build build, float texel_density, uint32_t bake_spp, const std::string& sky,
                           const view::PinholeCamera& camera) {
  GoldenScene g;
  g.dir = testing::fresh_temp_dir("golden-" + name);
  g.bundle = g.dir / (name + ".bake");
  g.camera = camera;
  samples::SceneBuilder builder;
  build(builder);
  builder.write((g.dir / (name + ".gltf")).string());
  BakeOptions options;
  options.input = (g.dir / (name + ".gltf")).string();
  options.output = g.bundle.string();
  options.backend.name = "cpu";
  options.atlas.texel_density = texel_density;
  options.lighting.spp = bake_spp;
  options.lighting.seed = 11;
  options.sky = sky;
  options.probes_enabled = false;
  options.svo_enabled = false;
  Diagnostics diagnostics;
  run_bake(options, diagnostics);

  const view::ViewScene scene = view::open_view_scene(g.bundle.string());
  const CpuReferenceIntegrator reference(*view::lighting_scene_of(scene)->source);
  IntegratorSettings settings;
  settings.spp = kPathTracedSpp;
  settings.seed = 977;
  settings.recorded_bounces = 1;
  g.traced = view::render_path_traced_view(scene, camera, kImageSide, kImageSide, reference, settings);
  return g;
}

// The golden test on the bundle in `directory` (the scene's, or a copy with an edited manifest).
GoldenComparison golden(const GoldenScene& g, const fs::path& directory) {
  const view::ViewScene scene = view::open_view_scene(directory.string());
  view::ViewRenderOptions options;
  options.width = options.height = kImageSide;
  const view::ViewImage baked = view::render_view(scene, g.camera, options);
  const double floor = read_json(directory / "manifest.json")["stats"]["error"]["floor"].get<double>();
  return testing::compare_with_path_traced(scene, g.camera, baked, g.traced, floor);
}

// A copy of the scene's bundle whose manifest `edit` changed.
template <typename Edit>
fs::path broken_copy(const GoldenScene& g, const std::string& name, Edit edit) {
  const fs::path copy = g.dir / name;
  fs::remove_all(copy);
  fs::copy(g.bundle, copy, fs::copy_options::recursive);
  nlohmann::json manifest = read_json(copy / "manifest.json");
  edit(manifest);
  std::ofstream(copy / "manifest.json") << manifest.dump();
  return copy;
}

nlohmann::json& instance_named(nlohmann::json& manifest, const std::string& name) {
  for (nlohmann::json& instance : manifest["instances"])
    if (instance["name"] == name) return instance;
  throw std::runtime_error("no instance " + name);
}

// The Cornell room at 8 texels per metre (12.5 cm texels on a 4 m room), 128 samples per texel, seen
// from inside the front wall: floor, ceiling light, both coloured walls and both boxes in view.
class GoldenCornellRoom : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new GoldenScene(bake_and_trace("cornell_room", samples::buildCornellRoom, 8, 128, "",
                                            view::look_at_camera({0, 2, 1.9f}, {0, 1.7f, -2}, {0, 1, 0}, 1.1)));
  }
  static void TearDownTestSuite() {
    fs::remove_all(scene_->dir);
    delete scene_;
  }
  static GoldenScene* scene_;
};
GoldenScene* GoldenCornellRoom::scene_ = nullptr;

TEST_F(GoldenCornellRoom, BakedViewMatchesThePathTracedReference) {
  EXPECT_EQ(scene_->traced.estimate.nonfinite_samples, 0u);
  const GoldenComparison g = golden(*scene_, scene_->bundle);
  testing::print_golden("cornell_room", g);
  EXPECT_GT(g.pixels, size_t(kImageSide * kImageSide * 9 / 10));
  EXPECT_LT(g.rel_mse, g.tolerance);
}

// The floor drawn with the back wall's lightmap (page and scale_offset swapped between the two).
TEST_F(GoldenCornellRoom, AnInstanceReadingAnotherInstancesLightmapFails) {
  const fs::path broken = broken_copy(*scene_, "swapped.bake", [](nlohmann::json& manifest) {
    nlohmann::json& floor = instance_named(manifest, "Floor");
    nlohmann::json& back = instance_named(manifest, "BackWall");
    std::swap(floor["page"], back["page"]);
    std::swap(floor["scale_offset"], back["scale_offset"]);
    if (floor.contains("rect") && back.contains("rect")) std::swap(floor["rect"], back["rect"]);
  });
  const GoldenComparison g = golden(*scene_, broken);
  testing::print_golden("cornell_room, Floor <-> BackWall", g);
  EXPECT_GT(g.rel_mse, kBrokenMargin * g.tolerance);
}

// The back wall's lightmap mirrored top to bottom (v -> 1 - v inside its rectangle): the light comes
// from the ceiling, so the wall is not symmetric that way.
TEST_F(GoldenCornellRoom, AMirroredScaleOffsetFails) {
  const fs::path broken = broken_copy(*scene_, "mirrored.bake", [](nlohmann::json& manifest) {
    nlohmann::json& so = instance_named(manifest, "BackWall")["scale_offset"];
    const double sy = so[1].get<double>(), oy = so[3].get<double>();
    so[1] = -sy;
    so[3] = oy + sy;
  });
  const GoldenComparison g = golden(*scene_, broken);
  testing::print_golden("cornell_room, BackWall mirrored in v", g);
  EXPECT_GT(g.rel_mse, kBrokenMargin * g.tolerance);
}

// The courtyard under a sky of (0.5, 0.6, 0.8) and a low sun (a directional light: hard shadows), at 2
// texels per metre and 64 samples per texel, seen from above the south side towards the north hall:
// paving with the low wall's and the buildings' shadows, four buildings, and sky.
class GoldenCourtyard : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new GoldenScene(bake_and_trace("courtyard", samples::buildCourtyard, 2, 64, "0.5,0.6,0.8",
                                            view::look_at_camera({0, 7, 10}, {0, 1, -4}, {0, 1, 0}, 1.0)));
  }
  static void TearDownTestSuite() {
    fs::remove_all(scene_->dir);
    delete scene_;
  }
  static GoldenScene* scene_;
};
GoldenScene* GoldenCourtyard::scene_ = nullptr;

TEST_F(GoldenCourtyard, BakedViewMatchesThePathTracedReference) {
  EXPECT_EQ(scene_->traced.estimate.nonfinite_samples, 0u);
  const GoldenComparison g = golden(*scene_, scene_->bundle);
  testing::print_golden("courtyard", g);
  EXPECT_GT(g.pixels, size_t(kImageSide * kImageSide / 2));
  EXPECT_LT(g.rel_mse, g.tolerance);
}

// The ground drawn with its lightmap mirrored in u: the shadows move.
TEST_F(GoldenCourtyard, AMirroredScaleOffsetFails) {
  const fs::path broken = broken_copy(*scene_, "mirrored.bake", [](nlohmann::json& manifest) {
    nlohmann::json& so = instance_named(manifest, "Ground")["scale_offset"];
    const double sx = so[0].get<double>(), ox = so[2].get<double>();
    so[0] = -sx;
    so[2] = ox + sx;
  });
  const GoldenComparison g = golden(*scene_, broken);
  testing::print_golden("courtyard, Ground mirrored in u", g);
  EXPECT_GT(g.rel_mse, kBrokenMargin * g.tolerance);
}

// A 4 m room lit only by punctual lights (KHR_lights_punctual): a warm point light low in the back
// right corner, whose light the box shadows on the floor and the left wall, and a spot light (cone
// 0.15 to 0.3 rad) tilted onto the floor left of the box, a soft-edged pool; white walls but a red
// left one.
void build_lamp_room(samples::SceneBuilder& scene) {
  const samples::MaterialId white = scene.addMaterial({.name = "White", .baseColor = {0.73f, 0.73f, 0.73f}});
  const samples::MaterialId red = scene.addMaterial({.name = "Red", .baseColor = {0.63f, 0.065f, 0.05f}});
  const float r = 2.0f, top = 4.0f;
  auto wall = [&](const char* name, samples::Quad quad, samples::MaterialId material) {
    samples::MeshBuilder mesh;
    mesh.addQuad(quad, material);
    scene.addMeshNode(name, mesh);
  };
  wall("Floor", samples::Quad::axisAligned({-r, 0, -r}, {r, 0, r}, {0, 1, 0}), white);
  wall("Ceiling", samples::Quad::axisAligned({-r, top, -r}, {r, top, r}, {0, -1, 0}), white);
  wall("BackWall", samples::Quad::axisAligned({-r, 0, -r}, {r, top, -r}, {0, 0, 1}), white);
  wall("FrontWall", samples::Quad::axisAligned({-r, 0, r}, {r, top, r}, {0, 0, -1}), white);
  wall("LeftWall", samples::Quad::axisAligned({-r, 0, -r}, {-r, top, r}, {1, 0, 0}), red);
  wall("RightWall", samples::Quad::axisAligned({r, 0, -r}, {r, top, r}, {-1, 0, 0}), white);
  samples::MeshBuilder box;
  box.addBox({.center = {0, 0.5f, 0}, .size = {1.0f, 1.0f, 1.0f}, .yawRadians = 0.4f}, white,
             samples::FaceDirection::Outward, samples::BoxFace::AllButBottom);
  scene.addMeshNode("Box", box, {0.2f, 0.0f, -0.6f});
  scene.addPointLight({.name = "Bulb", .position = {1.3f, 2.2f, -1.0f}, .color = {1.0f, 0.9f, 0.8f}, .intensity = 2.0f});
  scene.addSpotLight({.name = "Spot",
                      .position = {-0.2f, 3.8f, 0.8f},
                      .direction = {-1.0f, -3.8f, -2.3f},
                      .color = {0.8f, 0.9f, 1.0f},
                      .intensity = 40.0f,
                      .innerConeAngle = 0.15f,
                      .outerConeAngle = 0.3f});
}

// The lamp room at 8 texels per metre and 128 samples per texel, seen from inside the front wall.
class GoldenLampRoom : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new GoldenScene(bake_and_trace("lamp_room", build_lamp_room, 8, 128, "",
                                            view::look_at_camera({0, 2, 1.9f}, {0, 1.0f, -2}, {0, 1, 0}, 1.1)));
  }
  static void TearDownTestSuite() {
    fs::remove_all(scene_->dir);
    delete scene_;
  }
  static GoldenScene* scene_;
};
GoldenScene* GoldenLampRoom::scene_ = nullptr;

TEST_F(GoldenLampRoom, BakedViewMatchesThePathTracedReference) {
  EXPECT_EQ(scene_->traced.estimate.nonfinite_samples, 0u);
  const GoldenComparison g = golden(*scene_, scene_->bundle);
  testing::print_golden("lamp_room", g);
  EXPECT_GT(g.pixels, size_t(kImageSide * kImageSide * 9 / 10));
  EXPECT_LT(g.rel_mse, g.tolerance);
}

// The back wall drawn with its lightmap mirrored in u (along x): the bulb's bright patch moves across.
TEST_F(GoldenLampRoom, AMirroredScaleOffsetFails) {
  const fs::path broken = broken_copy(*scene_, "mirrored.bake", [](nlohmann::json& manifest) {
    nlohmann::json& so = instance_named(manifest, "BackWall")["scale_offset"];
    const double sx = so[0].get<double>(), ox = so[2].get<double>();
    so[0] = -sx;
    so[2] = ox + sx;
  });
  const GoldenComparison g = golden(*scene_, broken);
  testing::print_golden("lamp_room, BackWall mirrored in u", g);
  EXPECT_GT(g.rel_mse, kBrokenMargin * g.tolerance);
}

}  // namespace
}  // namespace exitance
