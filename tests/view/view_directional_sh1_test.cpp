// exitance-view's directional lightmaps (docs/view.md, "Directional lightmaps under normal maps"): a
// floor whose material has a normal map of one constant tilt (a 1-texel PNG in the glTF, no TANGENT,
// so the importer generates the frames from TEXCOORD_0), baked with --directional sh1, viewed from
// above. Every texel of the floor sees the same sky, so each pixel must equal a closed form:
//  - under a constant sky L: E(n)/pi = L (1 + n . n0) / 2, exact for a tilted normal under a
//    hemisphere-limited uniform sky (and exactly what RGB + L1 . (n - n0) gives, docs/bundle.md);
//  - under a sky of four constant quadrants (a 4 x 1 equirectangular image: columns split the
//    directions at x = 0 and z = 0), RGB = sum(Lq) / 4 and L1 = sum(Lq (sx, 1, sz)) / 8 (each octant
//    of the upper hemisphere integrates w to (sx, 1, sz) pi / 4): the pixel is albedo x
//    (RGB + L1 . (n - n0)), the L1 reconstruction the bundle defines. This sky has gradients along x
//    and z, so the tilt's direction matters: the same view with the tangent's handedness flipped,
//    with the tangent reversed, or with the L1 layers negated must fail the check.
// Tolerance: each texel's value RGB + L1 . d (d = n - n0) deviates from its mean by at most
// sd(RGB) + sum |d_k| sd(L1_k) (triangle inequality), each sd the spread of that channel over the
// floor's fully covered texels (all have the same expectation). A pixel is a convex (bilinear) mix
// of texels, so it lies within z such deviations when every texel does; z = 5 bounds the chance that
// any of the page's texels and channels (<= 3 x 400) exceeds it by 1200 x 2 Phi(-5) = 7e-4
// (Bonferroni, normal tails). Nothing is fitted to the bake.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/formats/lightmap_exr.h"
#include "exitance/formats/scene_file.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/view/path_traced_view.h"
#include "exitance/runtime/view/view_render.h"
#include "exitance/runtime/view/view_scene.h"
#include "scene_builder.h"
#include "support/fresh_temp_dir.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;

constexpr float kAlbedo[3] = {0.7f, 0.5f, 0.3f};
constexpr float kUniformSky[3] = {0.8f, 0.6f, 0.4f};
// The quadrant sky: radiance of image columns 0..3 (times kQuadrantColour per channel). Column c
// holds u = 0.5 + atan2(x, -z) / 2 pi in [c/4, (c+1)/4): (x < 0, z > 0), (x < 0, z < 0),
// (x >= 0, z < 0), (x > 0, z > 0) (common/environment_map.h).
constexpr float kQuadrant[4] = {1.0f, 0.1f, 0.4f, 2.0f};
constexpr int kQuadrantSx[4] = {-1, -1, 1, 1}, kQuadrantSz[4] = {1, -1, -1, 1};
constexpr float kQuadrantColour[3] = {1.0f, 0.8f, 0.6f};
// The normal map's tangent-space normal, before 8-bit quantization: tilted by 0.6 rad towards
// azimuth 0.8 rad in the texture's (u, up) plane.
constexpr double kTilt = 0.6, kAzimuth = 0.8;
constexpr double kZLimit = 5.0;

float component(Vec3 v, int c) { return c == 0 ? v.x : (c == 1 ? v.y : v.z); }

uint8_t to_byte(double m) { return uint8_t(std::lround(255.0 * (m + 1.0) / 2.0)); }

// The texel the PNG stores, and the unit tangent-space normal the importer decodes from it.
std::array<uint8_t, 3> normal_map_texel() {
  return {to_byte(std::sin(kTilt) * std::cos(kAzimuth)), to_byte(std::sin(kTilt) * std::sin(kAzimuth)),
          to_byte(std::cos(kTilt))};
}
Vec3 tangent_space_normal() {
  const std::array<uint8_t, 3> t = normal_map_texel();
  return normalize(Vec3{2.0f * t[0] / 255.0f - 1.0f, 2.0f * t[1] / 255.0f - 1.0f, 2.0f * t[2] / 255.0f - 1.0f});
}

// The builder's +Y floor quad has TEXCOORD_0 u along +z and v along +x (mesh_builder.cpp: edgeU is the
// axis after the flat one, edgeV the next); the test checks that on scene.bin. glTF's tangent frame:
// t along increasing u = +z, bitangent along decreasing v = -x (image up), n0 = +y.
Vec3 world_mapped_normal() {
  const Vec3 m = tangent_space_normal();
  return normalize(Vec3{0, 0, 1} * m.x + Vec3{-1, 0, 0} * m.y + Vec3{0, 1, 0} * m.z);
}

void write_png(const fs::path& path, const std::array<uint8_t, 3>& texel) {
  auto out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out && out->open(path.string(), OIIO::ImageSpec(1, 1, 3, OIIO::TypeDesc::UINT8)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, texel.data()));
  out->close();
}

void write_quadrant_sky(const fs::path& path) {
  std::vector<float> rgb;
  for (int column = 0; column < 4; ++column)
    for (int c = 0; c < 3; ++c) rgb.push_back(kQuadrant[column] * kQuadrantColour[c]);
  auto out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out && out->open(path.string(), OIIO::ImageSpec(4, 1, 3, OIIO::TypeDesc::FLOAT)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()));
  out->close();
}

// A 4 x 4 m floor at y = 0 facing +Y whose material has the normal map (glTF patched after the
// builder wrote it: images, textures, normalTexture).
fs::path write_floor(const fs::path& dir) {
  samples::SceneBuilder builder;
  samples::Material material;
  material.baseColor = {kAlbedo[0], kAlbedo[1], kAlbedo[2]};
  const auto id = builder.addMaterial(material);
  samples::MeshBuilder floor;
  floor.addQuad(samples::Quad::axisAligned({-2, 0, -2}, {2, 0, 2}, {0, 1, 0}), id);
  builder.addMeshNode("Floor", floor);
  const fs::path path = dir / "floor.gltf";
  builder.write(path.string());
  write_png(dir / "normal.png", normal_map_texel());
  nlohmann::json gltf = nlohmann::json::parse(std::ifstream(path));
  gltf["images"] = nlohmann::json::array({{{"uri", "normal.png"}}});
  gltf["textures"] = nlohmann::json::array({{{"source", 0}}});
  gltf["materials"][0]["normalTexture"] = {{"index", 0}};
  std::ofstream(path) << gltf.dump();
  return path;
}

fs::path bake(const fs::path& dir, const std::string& name, const std::string& sky, bool directional) {
  BakeOptions options;
  options.input = write_floor(dir).string();
  options.output = (dir / name).string();
  options.backend.name = "cpu";
  options.sky = sky;
  options.atlas.texel_density = 4;
  options.lighting.spp = 4096;
  options.probes_enabled = false;
  options.svo_enabled = false;
  if (directional) options.lighting.directional = DirectionalMode::Sh1;
  Diagnostics diagnostics;
  run_bake(options, diagnostics);
  return dir / name;
}

// Spread of one channel over the fully covered texels of every page.
double channel_spread(const loader::Bundle& bundle, const std::string& channel) {
  std::vector<double> values;
  for (size_t p = 0; p < bundle.pages().size(); ++p) {
    const formats::LightmapImage& page = bundle.page_image(p);
    const std::vector<float>& v = page.channels.at(channel);
    const std::vector<float>& a = page.channels.at("A");
    for (size_t i = 0; i < v.size(); ++i)
      if (a[i] >= 1.0f) values.push_back(v[i]);
  }
  double mean = 0, squares = 0;
  for (double v : values) mean += v / double(values.size());
  for (double v : values) squares += (v - mean) * (v - mean);
  return std::sqrt(squares / double(values.size() - 1));
}

struct Check {
  double worst_z = 0;  // largest |pixel - exact| in units of its derived deviation
  int outside = 0;     // pixel channels beyond kZLimit
};

// Renders the bundle from 1 m above the floor's centre (every pixel inside |x|, |z| < 0.6) and
// compares each pixel with albedo x exact[c].
Check check_view(const view::ViewScene& scene, const std::array<double, 3>& exact) {
  const Vec3 d = world_mapped_normal() - Vec3{0, 1, 0};
  std::array<double, 3> deviation{};
  for (int c = 0; c < 3; ++c) {
    const char* rgb[3] = {"R", "G", "B"};
    deviation[c] = channel_spread(scene.bundle, rgb[c]);
    if (scene.has_sh1_layers)
      for (int axis = 0; axis < 3; ++axis)
        deviation[c] += std::fabs(component(d, axis)) * channel_spread(scene.bundle, view::kSh1Channels[3 * axis + c]);
  }
  view::ViewRenderOptions options;
  options.width = options.height = 32;
  const view::ViewImage image =
      view::render_view(scene, view::look_at_camera({0, 1, 0}, {0, 0, 0}, {0, 0, -1}, 1.0), options);
  Check check;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const double expected = kAlbedo[c] * exact[size_t(c)], got = component(image.pixel(x, y), c);
        const double z = std::fabs(got - expected) / (kAlbedo[c] * deviation[size_t(c)] + 1e-6 * expected);
        check.worst_z = std::max(check.worst_z, z);
        check.outside += z > kZLimit;
      }
  return check;
}

// E/pi at the mapped normal under the quadrant sky, by the L1 reconstruction with exact coefficients.
std::array<double, 3> quadrant_sky_exact() {
  const Vec3 d = world_mapped_normal() - Vec3{0, 1, 0};
  std::array<double, 3> e{};
  for (int c = 0; c < 3; ++c) {
    double rgb = 0, l1[3] = {0, 0, 0};
    for (int q = 0; q < 4; ++q) {
      const double l = double(kQuadrant[q]) * kQuadrantColour[c];
      rgb += l / 4;
      l1[0] += l * kQuadrantSx[q] / 8, l1[1] += l / 8, l1[2] += l * kQuadrantSz[q] / 8;
    }
    e[size_t(c)] = rgb + l1[0] * d.x + l1[1] * d.y + l1[2] * d.z;
  }
  return e;
}

class ViewDirectionalSh1 : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(testing::fresh_temp_dir("view-directional-sh1"));
    write_quadrant_sky(*dir_ / "quadrants.exr");
    bake(*dir_, "uniform.bake", "0.8,0.6,0.4", true);
    bake(*dir_, "quadrants.bake", (*dir_ / "quadrants.exr").string(), true);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static fs::path* dir_;
};
fs::path* ViewDirectionalSh1::dir_ = nullptr;

// The importer's frames on the floor: generated from TEXCOORD_0, as world_mapped_normal assumes.
TEST_F(ViewDirectionalSh1, TheFloorCarriesTheNormalMapAndItsFrames) {
  const formats::SceneFile scene = formats::read_scene_file((*dir_ / "uniform.bake" / "scene.bin").string());
  ASSERT_GE(scene.materials[scene.triangles.material[0]].normal_texture.texture, 0);
  ASSERT_EQ(scene.tangents.size(), scene.triangles.positions.size());
  for (size_t c = 0; c < scene.tangents.size(); ++c) {
    EXPECT_EQ(scene.tangents[c], (formats::Float3{0, 0, 1})) << "corner " << c;  // +z: u grows along z
    EXPECT_EQ(scene.tangent_signs[c], -1.0f) << "corner " << c;  // b = -cross(+y, +z) = -x: v grows along +x
  }
}

TEST_F(ViewDirectionalSh1, UnderAUniformSkyPixelsAreTheTiltedNormalsIrradiance) {
  const view::ViewScene scene = view::open_view_scene((*dir_ / "uniform.bake").string());
  ASSERT_TRUE(scene.has_sh1_layers);
  const double cos_tilt = world_mapped_normal().y;
  std::array<double, 3> exact{};
  for (int c = 0; c < 3; ++c) exact[size_t(c)] = kUniformSky[c] * (1 + cos_tilt) / 2;
  const Check right = check_view(scene, exact);
  std::printf("[view sh1] uniform sky, cos tilt %.4f: worst pixel %.2f deviations\n", cos_tilt, right.worst_z);
  EXPECT_EQ(right.outside, 0);
  // L1 with the wrong sign (RGB - L1 . d): the view must disagree.
  const fs::path negated = *dir_ / "uniform-negated.bake";
  fs::copy(*dir_ / "uniform.bake", negated, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  for (const auto& entry : fs::directory_iterator(negated))
    if (entry.path().extension() == ".exr") {
      formats::LightmapImage page = formats::read_lightmap_exr(entry.path().string());
      for (const char* channel : view::kSh1Channels)
        for (float& v : page.channels.at(channel)) v = -v;
      formats::write_lightmap_exr(entry.path().string(), page);
    }
  const Check wrong = check_view(view::open_view_scene(negated.string()), exact);
  std::printf("[view sh1] uniform sky, L1 negated: %d pixel channels beyond %.0f, worst %.1f\n", wrong.outside, kZLimit,
              wrong.worst_z);
  EXPECT_GT(wrong.outside, 0);
}

TEST_F(ViewDirectionalSh1, UnderAQuadrantSkyPixelsFollowTheL1ReconstructionAndAWrongFrameFails) {
  const fs::path bundle = *dir_ / "quadrants.bake";
  const std::array<double, 3> exact = quadrant_sky_exact();
  const Check right = check_view(view::open_view_scene(bundle.string()), exact);
  std::printf("[view sh1] quadrant sky: exact %.4f %.4f %.4f, worst pixel %.2f deviations\n", exact[0], exact[1], exact[2],
              right.worst_z);
  EXPECT_EQ(right.outside, 0);

  // The same bundle with every tangent's handedness flipped, then with every tangent reversed.
  const formats::SceneFile original = formats::read_scene_file((bundle / "scene.bin").string());
  const auto with_frames = [&](const char* name, float tangent_factor, float sign_factor) {
    const fs::path broken = *dir_ / name;
    fs::copy(bundle, broken, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
    formats::SceneFile scene = original;
    for (formats::Float3& t : scene.tangents)
      for (float& v : t) v *= tangent_factor;
    for (float& w : scene.tangent_signs) w *= sign_factor;
    formats::write_scene_file((broken / "scene.bin").string(), scene);
    return check_view(view::open_view_scene(broken.string()), exact);
  };
  const Check flipped = with_frames("quadrants-flipped-handedness.bake", 1, -1);
  const Check reversed = with_frames("quadrants-reversed-tangent.bake", -1, 1);
  std::printf("[view sh1] quadrant sky, handedness flipped: %d beyond, worst %.1f; tangent reversed: %d beyond, worst %.1f\n",
              flipped.outside, flipped.worst_z, reversed.outside, reversed.worst_z);
  EXPECT_GT(flipped.outside, 0);
  EXPECT_GT(reversed.outside, 0);
}

// The path-traced view lights the normal-mapped normal (the true E(n)/pi the layers approximate):
// under the uniform sky the mean over its pixels is albedo x L (1 + n . n0) / 2, a z-test of the
// mean residual within 4 standard errors (pixels are independent estimates; their variances from
// PathTracedView::variance). E(n0)/pi = L would be 9.6 % higher, about 80 standard errors away.
TEST_F(ViewDirectionalSh1, ThePathTracedViewLightsTheMappedNormal) {
  const view::ViewScene scene = view::open_view_scene((*dir_ / "uniform.bake").string());
  const CpuReferenceIntegrator reference(*view::lighting_scene_of(scene)->source);
  IntegratorSettings settings;
  settings.spp = 256;
  settings.seed = 5;
  settings.recorded_bounces = 1;
  const int side = 16;
  const view::PathTracedView traced = view::render_path_traced_view(
      scene, view::look_at_camera({0, 1, 0}, {0, 0, 0}, {0, 0, -1}, 1.0), side, side, reference, settings);
  ASSERT_EQ(traced.estimate.texels.size(), size_t(side * side));
  const double cos_tilt = world_mapped_normal().y, pixels = double(side * side);
  for (int c = 0; c < 3; ++c) {
    double residual = 0, variance = 0;
    const double exact = kAlbedo[c] * kUniformSky[c] * (1 + cos_tilt) / 2;
    for (size_t p = 0; p < size_t(side * side); ++p) {
      residual += (traced.image.rgb[p * 3 + size_t(c)] - exact) / pixels;
      variance += traced.variance[p * 3 + size_t(c)] / (pixels * pixels);
    }
    std::printf("[view sh1] path traced, channel %d: exact %.5f, mean residual %+.2e, SE %.2e\n", c, exact, residual,
                std::sqrt(variance));
    EXPECT_LE(std::fabs(residual), 4 * std::sqrt(variance) + 1e-6 * exact) << "channel " << c;
  }
}

// Without sh1 layers (or with them ignored) the view reads the RGB layer as before: exactly
// albedo x the loader's bilinear E/pi, whatever the normal map.
TEST_F(ViewDirectionalSh1, WithoutLayersTheViewReadsTheRgbLayer) {
  view::ViewScene scene = view::open_view_scene((*dir_ / "quadrants.bake").string());
  scene.has_sh1_layers = false;
  std::array<double, 3> exact{};
  for (int q = 0; q < 4; ++q)
    for (int c = 0; c < 3; ++c) exact[size_t(c)] += double(kQuadrant[q]) * kQuadrantColour[c] / 4;
  const Check plain = check_view(scene, exact);
  std::printf("[view sh1] quadrant sky without the layers: worst pixel %.2f deviations of E(n0)/pi\n", plain.worst_z);
  EXPECT_EQ(plain.outside, 0);
}

}  // namespace
}  // namespace exitance
