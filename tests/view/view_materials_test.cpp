// exitance-view over scene.bin version 2's materials (view_materials.h): base colour textures with
// KHR_texture_transform, COLOR_0, emissive textures, MASK cut-outs, BLEND compositing and the image
// sky on a miss. A plane under a constant sky is baked once; its scene.bin records are then given
// textures in memory, and rays straight down (or up, into the sky) are shaded: each expected value
// is a closed form of the texel or colour the ray meets, and each would differ if the view ignored
// what it tests (the untextured value is checked to be far from it). Also an orthographic glTF
// camera over the same plane.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/common/environment_map.h"
#include "exitance/common/material.h"
#include "exitance/runtime/view/view_camera.h"
#include "exitance/runtime/view/view_render.h"
#include "exitance/runtime/view/view_scene.h"
#include "exitance/runtime/view/view_shading.h"
#include "scene_builder.h"
#include "support/fresh_temp_dir.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;
using view::ViewMode;

constexpr float kBase[3] = {0.6f, 0.5f, 0.4f};
const Vec3 kSky{0.8f, 0.6f, 0.4f};
const Vec3 kLeft{0.9f, 0.2f, 0.1f}, kRight{0.1f, 0.3f, 0.9f};

// A 2 x 2 plane at y = 0 facing +Y under the constant sky kSky, baked once.
const fs::path& plane_bundle() {
  static const fs::path bundle = [] {
    const fs::path dir = testing::fresh_temp_dir("view-materials");
    samples::SceneBuilder builder;
    samples::Material material;
    material.baseColor = {kBase[0], kBase[1], kBase[2]};
    const auto id = builder.addMaterial(material);
    samples::MeshBuilder plane;
    plane.addQuad(samples::Quad::axisAligned({-1, 0, -1}, {1, 0, 1}, {0, 1, 0}), id);
    builder.addMeshNode("Plane", plane);
    builder.write((dir / "plane.gltf").string());
    BakeOptions options;
    options.input = (dir / "plane.gltf").string();
    options.output = (dir / "plane.bake").string();
    options.backend.name = "cpu";
    options.atlas.texel_density = 8;
    options.lighting.spp = 4;
    options.sky = "0.8,0.6,0.4";
    options.probes_enabled = false;
    options.svo_enabled = false;
    Diagnostics diagnostics;
    run_bake(options, diagnostics);
    return dir / "plane.bake";
  }();
  return bundle;
}

// The plane's scene with TEXCOORD_0 = ((x + 1) / 2, (z + 1) / 2) at every corner and a 16 x 1
// texture whose left half is kLeft (alpha 0) and right half kRight (alpha 1), clamped: bilinear
// filtering mixes them only within 1/32 of u = 0.5.
view::ViewScene textured_plane() {
  view::ViewScene view = view::open_view_scene(plane_bundle().string());
  formats::SceneFile& scene = view.scene;
  scene.triangles.uv0.resize(scene.triangles.positions.size());
  for (size_t c = 0; c < scene.triangles.positions.size(); ++c)
    scene.triangles.uv0[c] = {(scene.triangles.positions[c][0] + 1) / 2, (scene.triangles.positions[c][2] + 1) / 2};
  formats::TextureRecord halves;
  halves.width = 16, halves.height = 1;
  halves.wrap_s = halves.wrap_t = formats::TextureWrap::ClampToEdge;
  for (uint32_t x = 0; x < 16; ++x) {
    const Vec3 c = x < 8 ? kLeft : kRight;
    halves.rgb.insert(halves.rgb.end(), {c.x, c.y, c.z});
    halves.alpha.push_back(x < 8 ? 0.0f : 1.0f);
  }
  scene.textures = {halves};
  return view;
}

Vec3 shade_down(const view::ViewScene& view, ViewMode mode, float x) {
  view::RayScratch scratch;
  return view::shade_primary_ray(view, mode, {x, 1.0f, 0.3f}, {0, -1, 0}, scratch);
}

void expect_close(Vec3 actual, Vec3 expected, const std::string& what) {
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(actual[c], expected[c], 1e-6f * std::max(1.0f, std::fabs(expected[c]))) << what << " channel " << c;
}

float difference(Vec3 a, Vec3 b) { return std::max({std::fabs(a.x - b.x), std::fabs(a.y - b.y), std::fabs(a.z - b.z)}); }

formats::MaterialRecord& plane_material(view::ViewScene& view) { return view.scene.materials[view.scene.triangles.material[0]]; }

TEST(ViewMaterials, AlbedoReadsTheBaseColourTextureThroughItsTransform) {
  view::ViewScene view = textured_plane();
  const Vec3 base{kBase[0], kBase[1], kBase[2]};
  const Vec3 untextured = shade_down(view, ViewMode::Albedo, -0.75f);
  formats::MaterialRecord& m = plane_material(view);
  m.base_color_texture.texture = 0;
  m.base_color_texture.offset = {0.25f, 0.0f};  // u' = u + 0.25
  // x = -0.75: u = 0.125, u' = 0.375 (left half); x = -0.1: u = 0.45, u' = 0.7 (right half).
  const Vec3 left = shade_down(view, ViewMode::Albedo, -0.75f), right = shade_down(view, ViewMode::Albedo, -0.1f);
  expect_close(left, diffuse_albedo_of(base * kLeft, m.metallic), "left half");
  expect_close(right, diffuse_albedo_of(base * kRight, m.metallic), "right half through the offset");
  EXPECT_GT(difference(left, untextured), 0.1f);
  EXPECT_GT(difference(right, left), 0.1f);
}

TEST(ViewMaterials, VertexColoursMultiplyTheAlbedo) {
  view::ViewScene view = textured_plane();
  const Vec3 untextured = shade_down(view, ViewMode::Albedo, 0.5f);
  const Vec3 colour{0.5f, 1.0f, 0.25f};
  view.scene.vertex_color.assign(view.scene.triangles.positions.size(), {colour.x, colour.y, colour.z});
  view.scene.vertex_alpha.assign(view.scene.triangles.positions.size(), 1.0f);
  expect_close(shade_down(view, ViewMode::Albedo, 0.5f), untextured * colour, "COLOR_0");
}

TEST(ViewMaterials, MaskCutOutShowsTheSkyAndTheRestIsUnchanged) {
  view::ViewScene view = textured_plane();
  const Vec3 opaque = shade_down(view, ViewMode::Lightmap, 0.5f);
  formats::MaterialRecord& m = plane_material(view);
  m.base_color_texture.texture = 0;
  m.alpha_mode = formats::AlphaMode::Mask;
  m.alpha_cutoff = 0.5f;
  // The left half (alpha 0) is cut out: the ray goes on to the sky. The right half (alpha 1) shows
  // its texel's albedo times the same lightmap value.
  expect_close(shade_down(view, ViewMode::Lightmap, -0.5f), kSky, "cut-out");
  const Vec3 albedo_ratio = diffuse_albedo_of(Vec3{kBase[0], kBase[1], kBase[2]} * kRight, m.metallic) /
                            diffuse_albedo_of(Vec3{kBase[0], kBase[1], kBase[2]}, m.metallic);
  expect_close(shade_down(view, ViewMode::Lightmap, 0.5f), opaque * albedo_ratio, "kept half");
  EXPECT_GT(difference(opaque, kSky), 0.1f);
  // first_surface passes the cut-out too: nothing is hit on the left.
  view::RayScratch scratch;
  EXPECT_FALSE(view::first_surface(view, {-0.5f, 1.0f, 0.3f}, {0, -1, 0}, scratch).has_value());
}

TEST(ViewMaterials, BlendCompositesOverWhatLiesBehind) {
  view::ViewScene view = textured_plane();
  const Vec3 opaque = shade_down(view, ViewMode::Lightmap, 0.5f);
  formats::MaterialRecord& m = plane_material(view);
  m.alpha_mode = formats::AlphaMode::Blend;
  m.base_alpha = 0.25f;
  expect_close(shade_down(view, ViewMode::Lightmap, 0.5f), opaque * 0.25f + kSky * 0.75f, "BLEND alpha 0.25");
}

TEST(ViewMaterials, EmissiveTextureAddsItsTexel) {
  view::ViewScene view = textured_plane();
  const Vec3 lit = shade_down(view, ViewMode::Lightmap, -0.5f);
  formats::MaterialRecord& m = plane_material(view);
  m.emission = {2.0f, 2.0f, 2.0f};
  m.emissive_texture.texture = 0;
  expect_close(shade_down(view, ViewMode::Lightmap, -0.5f), lit + kLeft * 2.0f, "left emission");
  expect_close(shade_down(view, ViewMode::Lightmap, 0.5f), lit + kRight * 2.0f, "right emission");
}

TEST(ViewMaterials, AMissShowsTheImageSkysTexel) {
  view::ViewScene view = textured_plane();
  formats::TextureRecord& map = view.scene.sky_environment;
  map.width = 4, map.height = 2;
  for (int i = 0; i < 8; ++i) map.rgb.insert(map.rgb.end(), {0.1f * float(i + 1), 0.5f, 1.0f - 0.1f * float(i)});
  view::RayScratch scratch;
  for (const Vec3 d : {Vec3{0, 1, 0}, Vec3{1, 0.2f, 0}, Vec3{-1, 0.3f, 0}}) {
    const Vec3 direction = normalize(d);
    const size_t i = size_t(environment_texel(direction, 4, 2)) * 3;
    const Vec3 expected{map.rgb[i], map.rgb[i + 1], map.rgb[i + 2]};
    expect_close(view::shade_primary_ray(view, ViewMode::Lightmap, {0, 1, 0}, direction, scratch), expected, "image sky");
    EXPECT_GT(difference(expected, kSky), 0.05f);
  }
  // Different directions read different texels (the test can tell a wrong mapping from a right one).
  EXPECT_NE(environment_texel(normalize(Vec3{1, 0.2f, 0}), 4, 2), environment_texel(normalize(Vec3{-1, 0.3f, 0}), 4, 2));
}

}  // namespace
// An orthographic camera (glTF xmag 0.8, ymag 0.4) looking straight down at the two-coloured plane:
// every ray is parallel, so the image is the same from 1 m and from 5 m above (a perspective camera's
// footprint would grow fivefold), the aspect ratio is xmag / ymag, and pixel column x sees world
// x = (2 (x + 0.5) / W - 1) * xmag: the left quarter the left colour, the right quarter the right one.
TEST(ViewOrthographicCamera, ParallelRaysSeeTheSameFromAnyDistance) {
  view::ViewScene view = textured_plane();
  formats::MaterialRecord& m = plane_material(view);
  m.base_color_texture.texture = 0;
  formats::SceneFile& scene = view.scene;
  scene.cameras.push_back({});
  formats::CameraRecord& camera = scene.cameras.back();
  camera.name = "TopCam";
  camera.node = int32_t(scene.nodes.size());
  camera.type = formats::CameraType::Orthographic;
  camera.xmag = 0.8f, camera.ymag = 0.4f, camera.znear = 0.01f, camera.zfar = 100.0f;
  formats::NodeRecord node;
  node.name = "Top";
  node.camera = int32_t(scene.cameras.size() - 1);
  node.in_scene = true;
  node.rotation = {-std::sqrt(0.5), 0, 0, std::sqrt(0.5)};  // -Z looks down -Y, +Y becomes -Z
  scene.nodes.push_back(node);
  view::ViewRenderOptions render;
  render.width = 32;
  render.height = 16;
  render.mode = ViewMode::Albedo;
  std::vector<view::ViewImage> images;
  for (double height : {1.0, 5.0}) {
    scene.nodes.back().translation = {0, height, 0};
    const view::GltfCameraView top = view::gltf_camera(scene, "TopCam");
    EXPECT_TRUE(top.camera.orthographic);
    EXPECT_NEAR(top.aspect_ratio, 2.0f, 1e-6f);
    images.push_back(view::render_view(view, top.camera, render));
  }
  const Vec3 base{kBase[0], kBase[1], kBase[2]};
  const Vec3 left = diffuse_albedo_of(base * kLeft, m.metallic), right = diffuse_albedo_of(base * kRight, m.metallic);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x) {
      expect_close(images[1].pixel(x, y), images[0].pixel(x, y), "pixel " + std::to_string(x) + "," + std::to_string(y));
      if (x < 8) expect_close(images[0].pixel(x, y), left, "left quarter");
      if (x >= 24) expect_close(images[0].pixel(x, y), right, "right quarter");
    }
}

}  // namespace exitance
