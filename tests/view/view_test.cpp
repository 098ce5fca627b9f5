// exitance-view against closed forms (docs/view.md): bundles baked here through the library, viewed
// through exitance::view (the code the tool runs) and through the exitance-view binary.
//  - a plane under a constant sky: E/pi = L on the plane, so a pixel on it is albedo x L, within the
//    bundle's own texel noise (4 standard deviations of the plane's texels; a bilinear mix of
//    texels has at most one texel's deviation); a ray that misses shows L exactly;
//  - albedo and normal modes on that plane are exact;
//  - a point light over a plane (E/pi = I h / (pi d^3), deterministic): pixels follow the closed form
//    within the lightmap's derived interpolation error, and the same bundle with its scale_offset
//    mirrored fails that check (what a golden test must catch);
//  - a white furnace (emission Le, albedo rho, closed) has E/pi = Le / (1 - rho) everywhere, so a
//    pixel shows rho Le / (1 - rho) + Le = Le / (1 - rho): through the lightmap on the walls, and
//    through the probes on an inner box whose lightmap texels were removed from scene.bin (what an
//    engine does for an object without texels), within the probes' own noise; --mode probes too;
//  - a glTF camera node under a translated parent, looking down: the view it gives;
//  - the error mode reads the error.Y layer; the binary writes the same pixels to EXR, a PNG of the
//    asked size, and refuses what it cannot do with one line and exit 2.
// No assertion depends on which of two coincident triangles a ray reports: every pixel checked lies
// inside one face.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "exitance/bake/command/bake_pipeline.h"
#include "exitance/common/material.h"
#include "exitance/formats/lightmap_exr.h"
#include "exitance/formats/scene_file.h"
#include "exitance/runtime/core/bvh4_walk.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/view/path_traced_view.h"
#include "exitance/runtime/view/view_camera.h"
#include "exitance/runtime/view/view_image_output.h"
#include "exitance/runtime/view/view_input_error.h"
#include "exitance/runtime/view/view_render.h"
#include "exitance/runtime/view/view_scene.h"
#include "scene_builder.h"
#include "support/fresh_temp_dir.h"
#include "support/independent_estimates.h"

namespace exitance {
namespace {

namespace fs = std::filesystem;
using view::ViewMode;

constexpr float kPlaneAlbedo[3] = {0.6f, 0.5f, 0.4f};
constexpr float kSky[3] = {0.8f, 0.6f, 0.4f};
constexpr float kFurnaceAlbedo = 0.5f;
constexpr float kFurnaceEmission[3] = {0.5f, 0.25f, 0.125f};

Vec3 channel_array(const float (&c)[3]) { return {c[0], c[1], c[2]}; }
float component(Vec3 v, int c) { return c == 0 ? v.x : (c == 1 ? v.y : v.z); }

BakeOptions small_bake(const fs::path& input, const fs::path& output) {
  BakeOptions options;
  options.input = input.string();
  options.output = output.string();
  options.backend.name = "cpu";
  options.atlas.texel_density = 16;
  options.lighting.spp = 16;
  options.svo_enabled = false;
  return options;
}

// A 2 x 2 quad at y = 0 facing +Y, split at x = 0 into two materials when `two_colours`.
void add_floor(samples::SceneBuilder& builder, samples::MaterialId left, samples::MaterialId right) {
  samples::MeshBuilder west, east;
  west.addQuad(samples::Quad::axisAligned({-1, 0, -1}, {0, 0, 1}, {0, 1, 0}), left);
  east.addQuad(samples::Quad::axisAligned({0, 0, -1}, {1, 0, 1}, {0, 1, 0}), right);
  builder.addMeshNode("West", west);
  builder.addMeshNode("East", east);
}

// Standard deviation of the fully covered texels of every page, per channel: the bundle's own noise.
Vec3 texel_standard_deviation(const loader::Bundle& bundle) {
  Vec3 sd;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> values;
    for (size_t p = 0; p < bundle.pages().size(); ++p) {
      const formats::LightmapImage& page = bundle.page_image(p);
      const std::vector<float>& v = page.channels.at(c == 0 ? "R" : (c == 1 ? "G" : "B"));
      const std::vector<float>& a = page.channels.at("A");
      for (size_t i = 0; i < v.size(); ++i)
        if (a[i] >= 1.0f) values.push_back(v[i]);
    }
    const testing::MeanAndError m = testing::mean_and_standard_error(values);
    sd[c] = float(m.standard_error * std::sqrt(double(m.count)));
  }
  return sd;
}

class PlaneUnderSky : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(testing::fresh_temp_dir("view-plane"));
    samples::SceneBuilder builder;
    samples::Material material;
    material.baseColor = {kPlaneAlbedo[0], kPlaneAlbedo[1], kPlaneAlbedo[2]};
    const auto id = builder.addMaterial(material);
    add_floor(builder, id, id);
    builder.write((*dir_ / "plane.gltf").string());
    BakeOptions options = small_bake(*dir_ / "plane.gltf", *dir_ / "plane.bake");
    options.sky = "0.8,0.6,0.4";
    options.probes_enabled = false;
    Diagnostics diagnostics;
    run_bake(options, diagnostics);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static fs::path bundle() { return *dir_ / "plane.bake"; }
  static fs::path bundle_without_error_layer();
  // From 1 m above the plane's centre looking down: every pixel lies inside the plane (|x|, |z| < 0.6).
  static view::PinholeCamera top_camera() { return view::look_at_camera({0, 1, 0}, {0, 0, 0}, {0, 0, -1}, 1.0); }
  static fs::path* dir_;
};
fs::path* PlaneUnderSky::dir_ = nullptr;

TEST_F(PlaneUnderSky, PixelsOnThePlaneAreAlbedoTimesTheSky) {
  const view::ViewScene scene = view::open_view_scene(bundle().string());
  const Vec3 sd = texel_standard_deviation(scene.bundle);
  view::ViewRenderOptions options;
  options.width = options.height = 48;
  const view::ViewImage image = view::render_view(scene, top_camera(), options);
  double worst_z = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const double exact = double(kPlaneAlbedo[c]) * kSky[c], got = component(image.pixel(x, y), c);
        const double tolerance = 4.0 * kPlaneAlbedo[c] * component(sd, c) + 1e-5 * exact;
        ASSERT_LE(std::fabs(got - exact), tolerance) << "pixel " << x << "," << y << " channel " << c;
        if (component(sd, c) > 0) worst_z = std::max(worst_z, std::fabs(got - exact) / (kPlaneAlbedo[c] * component(sd, c)));
      }
  std::printf("[view] plane under sky: texel sd %.3g %.3g %.3g, worst pixel %.2f texel sd\n", sd.x, sd.y, sd.z, worst_z);
}

// The path-traced view (docs/view.md, "The path-traced view") on the CPU reference: albedo x sky on the
// plane within 4 of the pixels' own standard errors, 0 on the back of the single-sided plane, the sky
// exactly on a miss.
TEST_F(PlaneUnderSky, PathTracedPixelsAreAlbedoTimesTheSkyBlackBehindAndSkyOnAMiss) {
  const view::ViewScene scene = view::open_view_scene(bundle().string());
  const CpuReferenceIntegrator reference(*view::lighting_scene_of(scene)->source);
  IntegratorSettings settings;
  settings.spp = 16;
  settings.recorded_bounces = 1;
  const view::PathTracedView top = view::render_path_traced_view(scene, top_camera(), 16, 16, reference, settings);
  ASSERT_EQ(top.estimate.texels.size(), 16u * 16u);
  for (size_t p = 0; p < 16 * 16; ++p)
    for (int c = 0; c < 3; ++c) {
      const double exact = double(kPlaneAlbedo[c]) * kSky[c], got = top.image.rgb[p * 3 + size_t(c)];
      ASSERT_LE(std::fabs(got - exact), 4.0 * std::sqrt(double(top.variance[p * 3 + size_t(c)])) + 1e-5 * exact)
          << "pixel " << p << " channel " << c;
    }
  // From below: the back of a single-sided plane absorbs (no texel is traced, the pixel is 0).
  const view::PathTracedView below = view::render_path_traced_view(
      scene, view::look_at_camera({0, -1, 0}, {0, 0, 0}, {0, 0, -1}, 1.0), 8, 8, reference, settings);
  EXPECT_TRUE(below.estimate.texels.empty());
  for (float v : below.image.rgb) ASSERT_EQ(v, 0.0f);
  // Looking up: every ray misses and shows the sky.
  const view::PathTracedView up = view::render_path_traced_view(
      scene, view::look_at_camera({0, 1, 0}, {0, 2, 0}, {0, 0, -1}, 1.0), 8, 8, reference, settings);
  EXPECT_TRUE(up.estimate.texels.empty());
  for (size_t p = 0; p < 8 * 8; ++p)
    for (int c = 0; c < 3; ++c) ASSERT_EQ(up.image.rgb[p * 3 + size_t(c)], kSky[c]);
}

TEST_F(PlaneUnderSky, ARayThatMissesShowsTheSky) {
  const view::ViewScene scene = view::open_view_scene(bundle().string());
  view::ViewRenderOptions options;
  options.width = options.height = 16;
  const view::ViewImage up = view::render_view(scene, view::look_at_camera({0, 1, 0}, {0, 2, 0}, {0, 0, -1}, 1.0), options);
  for (int y = 0; y < up.height; ++y)
    for (int x = 0; x < up.width; ++x)
      for (int c = 0; c < 3; ++c) ASSERT_EQ(component(up.pixel(x, y), c), kSky[c]);
  // Albedo and normal views show nothing (0) where no surface is.
  options.mode = ViewMode::Albedo;
  const view::ViewImage empty = view::render_view(scene, view::look_at_camera({0, 1, 0}, {0, 2, 0}, {0, 0, -1}, 1.0), options);
  EXPECT_EQ(empty.pixel(8, 8).x, 0.0f);
}

// The library refuses a size or sampling it cannot draw (the tool and the preview check first).
TEST_F(PlaneUnderSky, RenderViewRefusesAnEmptyOrHugeImage) {
  const view::ViewScene scene = view::open_view_scene(bundle().string());
  for (const auto [w, h, aa] : {std::array{0, 8, 1}, std::array{8, 0, 1}, std::array{16385, 8, 1}, std::array{8, 8, 0},
                                std::array{8, 8, 17}}) {
    view::ViewRenderOptions options;
    options.width = w, options.height = h, options.samples_per_axis = aa;
    EXPECT_THROW(view::render_view(scene, top_camera(), options), std::invalid_argument) << w << "x" << h << " aa " << aa;
  }
}

TEST_F(PlaneUnderSky, AlbedoAndNormalModesAreExact) {
  const view::ViewScene scene = view::open_view_scene(bundle().string());
  view::ViewRenderOptions options;
  options.width = options.height = 24;
  options.samples_per_axis = 2;
  options.mode = ViewMode::Albedo;
  const view::ViewImage albedo = view::render_view(scene, top_camera(), options);
  options.mode = ViewMode::Normal;
  const view::ViewImage normal = view::render_view(scene, top_camera(), options);
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 24; ++x)
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(component(albedo.pixel(x, y), c), kPlaneAlbedo[c]) << x << "," << y;
        ASSERT_EQ(component(normal.pixel(x, y), c), c == 1 ? 1.0f : 0.5f) << x << "," << y;
      }
}

// bake writes error.Y into every bundle; a bundle of another writer may lack it (a copy without it).
fs::path PlaneUnderSky::bundle_without_error_layer() {
  const fs::path copy = *dir_ / "without-error.bake";
  if (fs::exists(copy)) return copy;
  fs::copy(bundle(), copy, fs::copy_options::recursive);
  const std::string page_file = (copy / "lightmap-0.exr").string();
  formats::LightmapImage page = formats::read_lightmap_exr(page_file);
  page.channels.erase("error.Y");
  formats::write_lightmap_exr(page_file, page);
  nlohmann::json manifest = nlohmann::json::parse(std::ifstream(copy / "manifest.json"));
  auto& channels = manifest["pages"][0]["channels"];
  channels.erase(std::remove(channels.begin(), channels.end(), "error.Y"), channels.end());
  std::ofstream(copy / "manifest.json") << manifest.dump(2);
  return copy;
}

TEST_F(PlaneUnderSky, ErrorModeReadsTheErrorLayer) {
  // A copy of the bundle whose page gains error.Y = 0.25 (+ 0.5 on the west half of the page).
  const fs::path copy = *dir_ / "with-error.bake";
  fs::remove_all(copy);
  fs::copy(bundle(), copy, fs::copy_options::recursive);
  const std::string page_file = (copy / "lightmap-0.exr").string();
  formats::LightmapImage page = formats::read_lightmap_exr(page_file);
  page.channels["error.Y"].assign(page.channels.at("R").size(), 0.25f);
  formats::write_lightmap_exr(page_file, page);
  const view::ViewScene scene = view::open_view_scene(copy.string());
  ASSERT_TRUE(scene.bundle.has_lightmap_channel(view::kErrorChannel));
  view::ViewRenderOptions options;
  options.width = options.height = 8;
  options.mode = ViewMode::Error;
  const view::ViewImage image = view::render_view(scene, top_camera(), options);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) ASSERT_NEAR(image.pixel(x, y).y, 0.25f, 1e-7f);
  // Without the layer the tool refuses the mode (below); the library reports its absence.
  EXPECT_TRUE(view::open_view_scene(bundle().string()).bundle.has_lightmap_channel(view::kErrorChannel));
  EXPECT_FALSE(view::open_view_scene(bundle_without_error_layer().string()).bundle.has_lightmap_channel(view::kErrorChannel));
}

int run(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST_F(PlaneUnderSky, TheBinaryWritesTheSamePixelsAndRefusesBadInput) {
  const std::string tool = EXITANCE_VIEW, b = bundle().string(), out = (*dir_ / "view").string();
  const std::string camera = " --look-from 0,1,0 --look-at 0,0,0 --up 0,0,-1 --yfov 1 --size 32,24 ";
  ASSERT_EQ(run(tool + " " + b + camera + "--aa 2 -o " + out + ".exr 2>/dev/null"), 0);
  const formats::LightmapImage exr = formats::read_lightmap_exr(out + ".exr");
  const view::ViewScene scene = view::open_view_scene(b);
  view::ViewRenderOptions options;
  options.width = 32;
  options.height = 24;
  options.samples_per_axis = 2;
  const view::ViewImage image = view::render_view(
      scene, view::look_at_camera({0, 1, 0}, {0, 0, 0}, {0, 0, -1}, 1.0), options);
  ASSERT_EQ(exr.width, 32);
  ASSERT_EQ(exr.height, 24);
  for (int i = 0; i < 32 * 24; ++i) ASSERT_EQ(exr.channels.at("G")[size_t(i)], image.rgb[size_t(i) * 3 + 1]);

  ASSERT_EQ(run(tool + " " + b + camera + "--exposure 1 -o " + out + ".png 2>/dev/null"), 0);
  const std::string png = read_text(out + ".png");
  ASSERT_GT(png.size(), 24u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  // IHDR: width and height, big-endian, at bytes 16..23.
  EXPECT_EQ((uint8_t(png[18]) << 8) | uint8_t(png[19]), 32);
  EXPECT_EQ((uint8_t(png[22]) << 8) | uint8_t(png[23]), 24);

  // The mode the bundle cannot show: exit 2, one line naming the bundle and the layer, no file.
  const std::string err = (*dir_ / "stderr.txt").string();
  const std::string without = bundle_without_error_layer().string();
  EXPECT_EQ(run(tool + " " + without + camera + "--mode error -o " + out + "-error.png 2>" + err), 2);
  const std::string message = read_text(err);
  EXPECT_NE(message.find(without), std::string::npos) << message;
  EXPECT_NE(message.find("error.Y"), std::string::npos) << message;
  EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
  EXPECT_FALSE(fs::exists(out + "-error.png"));
}

TEST(ViewToneCurve, ExposureCurveAndSrgb) {
  // 0 stays 0; Y = 1 maps to 0.5 (x / (1 + Y)), sRGB 0.5 -> 188; huge values saturate; NaN -> 0.
  EXPECT_EQ(view::tone_map_to_srgb8({0, 0, 0}, 0)[0], 0);
  EXPECT_EQ(view::tone_map_to_srgb8({1, 1, 1}, 0)[1], 188);
  EXPECT_EQ(view::tone_map_to_srgb8({0.5f, 0.5f, 0.5f}, 1)[2], 188);  // 2^1 exposure
  EXPECT_EQ(view::tone_map_to_srgb8({1e30f, 1e30f, 1e30f}, 0)[0], 255);
  EXPECT_EQ(view::tone_map_to_srgb8({NAN, -1, 0}, 0)[0], 0);
}

// --- A point light over a plane: a lightmap that varies, read through the instance's scale_offset ---

// E/pi at (x, 0, z) under a point light of intensity I (W/sr) at (lx, h, lz): I h / (pi d^3).
constexpr float kLight[3] = {0.3f, 1.0f, -0.2f};
double point_light_e_over_pi(double x, double z) {
  const double dx = x - kLight[0], dz = z - kLight[2], h = kLight[1];
  const double d2 = dx * dx + h * h + dz * dz;
  return h / (M_PI * d2 * std::sqrt(d2));
}

// The largest |grad f| of E/pi over the square |x|, |z| <= half (central differences).
double max_gradient(double half) {
  double worst = 0;
  const double step = 1e-4;
  for (int i = 0; i <= 100; ++i)
    for (int j = 0; j <= 100; ++j) {
      const double x = -half + 2 * half * i / 100, z = -half + 2 * half * j / 100;
      const double fx = (point_light_e_over_pi(x + step, z) - point_light_e_over_pi(x - step, z)) / (2 * step);
      const double fz = (point_light_e_over_pi(x, z + step) - point_light_e_over_pi(x, z - step)) / (2 * step);
      worst = std::max(worst, std::hypot(fx, fz));
    }
  return worst;
}

// The largest |f_xx| + |f_zz| of E/pi over the square |x|, |z| <= half (central differences).
double max_second_derivative_sum(double half) {
  double worst = 0;
  const double step = 1e-3;
  for (int i = 0; i <= 100; ++i)
    for (int j = 0; j <= 100; ++j) {
      const double x = -half + 2 * half * i / 100, z = -half + 2 * half * j / 100, f = point_light_e_over_pi(x, z);
      const double fxx = (point_light_e_over_pi(x + step, z) - 2 * f + point_light_e_over_pi(x - step, z)) / (step * step);
      const double fzz = (point_light_e_over_pi(x, z + step) - 2 * f + point_light_e_over_pi(x, z - step)) / (step * step);
      worst = std::max(worst, std::fabs(fxx) + std::fabs(fzz));
    }
  return worst;
}

struct PointLightComparison {
  int pixels = 0, outside_tolerance = 0;
  double worst_ratio = 0;  // |error| / tolerance
};

// Every pixel of a view from above whose hit lies in |x|, |z| < 0.8 (at least 3 texels inside the
// quad), against albedo x the closed form. The tolerance is derived, not tuned: bilinear
// interpolation between texel centres is off by at most (s^2 / 8) (|f_xx| + |f_zz|) for a texel of
// world size s, a texel holding its area's mean instead of its centre's value by (s^2 / 24) of the
// same; a texel that the quad's diagonal (x = z) crosses holds E/pi at the centroid of its part on
// the triangle that covers most of it (the rasterizer's rule), up to s / sqrt(2) from its centre,
// so within 2 texels of the diagonal |grad f| s / sqrt(2) is added; plus 4 x the bundle's own
// estimated relative error of a texel.
PointLightComparison compare_with_point_light(const view::ViewScene& scene, double relative_error) {
  const view::PinholeCamera camera = view::look_at_camera({0, 1.5f, 0}, {0, 0, 0}, {0, 0, -1}, 1.2);
  view::ViewRenderOptions options;
  options.width = options.height = 40;
  const view::ViewImage image = view::render_view(scene, camera, options);
  float texel = 0;
  for (float s : scene.scene.texels.triangle_texel_size) texel = std::max(texel, s);
  const double curvature = max_second_derivative_sum(0.8), gradient = max_gradient(0.8);
  PointLightComparison result;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const Vec3 d = view::primary_ray_direction(camera, x + 0.5, y + 0.5, image.width, image.height);
      const double t = -double(camera.eye.y) / d.y;
      const double px = camera.eye.x + t * d.x, pz = camera.eye.z + t * d.z;
      if (!(std::fabs(px) < 0.8 && std::fabs(pz) < 0.8)) continue;
      const double f = point_light_e_over_pi(px, pz);
      const bool near_diagonal = std::fabs(px - pz) / std::sqrt(2.0) < 2 * texel;
      const double off_centre = near_diagonal ? gradient * texel / std::sqrt(2.0) : 0.0;
      const double tolerance =
          kPlaneAlbedo[0] * (double(texel) * texel * (1.0 / 8 + 1.0 / 24) * curvature + off_centre + 4 * relative_error * f) +
          1e-6;
      const double error = std::fabs(image.pixel(x, y).x - kPlaneAlbedo[0] * f);
      ++result.pixels;
      if (error > tolerance) ++result.outside_tolerance;
      result.worst_ratio = std::max(result.worst_ratio, error / tolerance);
    }
  return result;
}

TEST(ViewPointLight, PixelsFollowTheLightmapThroughScaleOffsetAndABrokenOneFails) {
  const fs::path dir = testing::fresh_temp_dir("view-point-light");
  samples::SceneBuilder builder;
  samples::Material material;
  material.baseColor = {kPlaneAlbedo[0], kPlaneAlbedo[1], kPlaneAlbedo[2]};
  samples::MeshBuilder plane;
  plane.addQuad(samples::Quad::axisAligned({-1, 0, -1}, {1, 0, 1}, {0, 1, 0}), builder.addMaterial(material));
  builder.addMeshNode("Plane", plane);
  builder.addPointLight({.name = "Lamp", .position = {kLight[0], kLight[1], kLight[2]}});
  builder.write((dir / "lamp.gltf").string());
  BakeOptions options = small_bake(dir / "lamp.gltf", dir / "lamp.bake");
  options.probes_enabled = false;
  Diagnostics diagnostics;
  run_bake(options, diagnostics);
  const nlohmann::json manifest = nlohmann::json::parse(read_text(dir / "lamp.bake" / "manifest.json"));
  const double relative_error = manifest["stats"]["estimated_relative_error"].get<double>();

  const PointLightComparison good = compare_with_point_light(view::open_view_scene((dir / "lamp.bake").string()), relative_error);
  std::printf("[view] point light: %d pixels, estimated relative error %.3g, worst |error| / tolerance %.3f\n", good.pixels,
              relative_error, good.worst_ratio);
  EXPECT_GT(good.pixels, 500);
  EXPECT_EQ(good.outside_tolerance, 0);

  // The same bundle with the instance's scale_offset mirrored in u: the view must disagree.
  nlohmann::json broken = manifest;
  auto& so = broken["instances"][0]["scale_offset"];
  const double sx = so[0].get<double>(), ox = so[2].get<double>();
  so[0] = -sx;
  so[2] = ox + sx;
  std::ofstream(dir / "lamp.bake" / "manifest.json") << broken.dump();
  const PointLightComparison bad = compare_with_point_light(view::open_view_scene((dir / "lamp.bake").string()), relative_error);
  std::printf("[view] point light, mirrored scale_offset: %d of %d pixels outside the tolerance\n", bad.outside_tolerance,
              bad.pixels);
  EXPECT_GT(bad.outside_tolerance, bad.pixels / 4);
  fs::remove_all(dir);
}

// --- The furnace: lightmap on the walls, probes on an inner box without texels ---------------------

// scene.bin without the live texels of `instance`: what a bake of a scene whose object has no
// lightmap (a dynamic object) records. Texel side tables are re-indexed; the file is re-validated.
void remove_instance_texels(const fs::path& scene_bin, uint32_t instance) {
  formats::SceneFile scene = formats::read_scene_file(scene_bin.string());
  formats::TexelGBufferRecords& g = scene.texels;
  std::vector<int64_t> new_index(g.texels.size(), -1);
  std::vector<formats::TexelRecord> kept;
  size_t first = 0;
  for (formats::TexelPageRecord& page : g.pages) {
    uint32_t live = 0;
    for (size_t i = first; i < first + page.live_texels; ++i)
      if (scene.triangles.instance[g.texels[i].triangle] != instance) {
        new_index[i] = int64_t(kept.size());
        kept.push_back(g.texels[i]);
        ++live;
      }
    first += page.live_texels;
    page.live_texels = live;
  }
  g.texels = kept;
  std::vector<formats::PartialCoverageRecord> partial;
  for (auto p : g.partial_coverage)
    if (new_index[p.texel] >= 0) partial.push_back({uint32_t(new_index[p.texel]), p.coverage});
  g.partial_coverage = partial;
  std::vector<formats::MovedTexelRecord> moved;
  for (auto m : g.moved)
    if (new_index[m.texel] >= 0) moved.push_back({uint32_t(new_index[m.texel]), m.position});
  g.moved = moved;
  for (size_t t = 0; t < scene.triangles.count(); ++t)
    if (scene.triangles.instance[t] == instance) g.triangle_texel_size[t] = 0;
  formats::write_scene_file(scene_bin.string(), scene);
}

class Furnace : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(testing::fresh_temp_dir("view-furnace"));
    samples::SceneBuilder builder;
    samples::Material material;
    material.baseColor = {kFurnaceAlbedo, kFurnaceAlbedo, kFurnaceAlbedo};
    material.emissiveColor = {kFurnaceEmission[0], kFurnaceEmission[1], kFurnaceEmission[2]};
    const auto id = builder.addMaterial(material);
    samples::MeshBuilder box, inner;
    box.addBox({.center = {0, 1, 0}, .size = {2, 2, 2}}, id, samples::FaceDirection::Inward);
    inner.addBox({.center = {0, 0.6f, 0}, .size = {0.6f, 0.6f, 0.6f}}, id, samples::FaceDirection::Outward);
    builder.addMeshNode("Furnace", box);
    builder.addMeshNode("Object", inner);
    builder.write((*dir_ / "furnace.gltf").string());
    BakeOptions options = small_bake(*dir_ / "furnace.gltf", *dir_ / "furnace.bake");
    options.atlas.texel_density = 8;
    options.probe_spacing = 0.5f;
    options.probe_spp = 256;
    Diagnostics diagnostics;
    run_bake(options, diagnostics);
    remove_instance_texels(*dir_ / "furnace.bake" / "scene.bin", 1);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static Vec3 exact() {
    return channel_array(kFurnaceEmission) / (1.0f - kFurnaceAlbedo);
  }
  // Spread of the probes' E/pi (normal +Y) over the usable probes, per channel: their own noise.
  static Vec3 probe_standard_deviation(const view::ViewScene& scene) {
    Vec3 sd;
    const formats::ProbeGrid& grid = *scene.bundle.probe_grid();
    for (int c = 0; c < 3; ++c) {
      std::vector<double> values;
      for (const formats::ProbeRecord& p : grid.probes)
        if (formats::probe_is_usable(p))
          values.push_back(scene.bundle.probe_irradiance_over_pi(p.position, {0, 1, 0}).irradiance_over_pi[size_t(c)]);
      const testing::MeanAndError m = testing::mean_and_standard_error(values);
      sd[c] = float(m.standard_error * std::sqrt(double(m.count)));
    }
    return sd;
  }
  static fs::path* dir_;
};
fs::path* Furnace::dir_ = nullptr;

// Checks every pixel of `image` against Le / (1 - rho) within 4 x rho x sd (+ float rounding).
void expect_furnace_pixels(const view::ViewImage& image, Vec3 exact, Vec3 sd, const char* what) {
  double worst_z = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const double got = component(image.pixel(x, y), c), e = component(exact, c);
        const double tolerance = 4.0 * kFurnaceAlbedo * component(sd, c) + 1e-5 * e;
        ASSERT_LE(std::fabs(got - e), tolerance) << what << ": pixel " << x << "," << y << " channel " << c;
        if (component(sd, c) > 0) worst_z = std::max(worst_z, std::fabs(got - e) / (kFurnaceAlbedo * component(sd, c)));
      }
  std::printf("[view] furnace %s: sd %.3g %.3g %.3g, worst pixel %.2f sd\n", what, sd.x, sd.y, sd.z, worst_z);
}

TEST_F(Furnace, AnInstanceWithoutTexelsIsLitByTheProbes) {
  const view::ViewScene scene = view::open_view_scene((*dir_ / "furnace.bake").string());
  ASSERT_EQ(scene.instance_has_texels, (std::vector<uint8_t>{1, 0}));
  ASSERT_TRUE(scene.bundle.has_probes());
  // Looking at the inner box's top face from above: every pixel inside it (|x|, |z| < 0.3 at y = 0.9).
  view::ViewRenderOptions options;
  options.width = options.height = 16;
  const view::ViewImage image = view::render_view(scene, view::look_at_camera({0, 1.8f, 0}, {0, 0.9f, 0}, {0, 0, -1}, 0.5), options);
  expect_furnace_pixels(image, exact(), probe_standard_deviation(scene), "inner box from probes");
}

TEST_F(Furnace, WallsAreLitByTheLightmap) {
  const view::ViewScene scene = view::open_view_scene((*dir_ / "furnace.bake").string());
  // The floor between the inner box and the wall (x in 0.45 .. 0.95), seen from above.
  view::ViewRenderOptions options;
  options.width = options.height = 16;
  const view::ViewImage image =
      view::render_view(scene, view::look_at_camera({0.7f, 1.9f, 0}, {0.7f, 0, 0}, {0, 0, -1}, 0.2), options);
  expect_furnace_pixels(image, exact(), texel_standard_deviation(scene.bundle), "floor from the lightmap");
}

TEST_F(Furnace, ProbesModeLightsEverySurfaceFromTheProbes) {
  const view::ViewScene scene = view::open_view_scene((*dir_ / "furnace.bake").string());
  view::ViewRenderOptions options;
  options.width = options.height = 16;
  options.mode = ViewMode::Probes;
  const view::ViewImage image =
      view::render_view(scene, view::look_at_camera({0.7f, 1.9f, 0}, {0.7f, 0, 0}, {0, 0, -1}, 0.2), options);
  expect_furnace_pixels(image, exact(), probe_standard_deviation(scene), "floor from the probes");
}

TEST_F(Furnace, NearestChildFirstWalkFindsTheSameNearestDistance) {
  // The view's walk order (nearest child first) against the runtime's (storage order): the same
  // nearest distance for every ray (which of two equally near triangles is reported may differ).
  const formats::SceneFile scene = formats::read_scene_file((*dir_ / "furnace.bake" / "scene.bin").string());
  const auto corners = [&](uint32_t t, Vec3& p0, Vec3& p1, Vec3& p2) {
    const auto& p = scene.triangles.positions;
    p0 = {p[3 * t][0], p[3 * t][1], p[3 * t][2]};
    p1 = {p[3 * t + 1][0], p[3 * t + 1][1], p[3 * t + 1][2]};
    p2 = {p[3 * t + 2][0], p[3 * t + 2][1], p[3 * t + 2][2]};
  };
  std::vector<uint32_t> stack;
  uint32_t state = 12345;
  const auto uniform = [&] {
    state = state * 1664525u + 1013904223u;
    return float(state >> 8) / float(1u << 24);
  };
  for (int i = 0; i < 4000; ++i) {
    const Vec3 origin{uniform() * 1.8f - 0.9f, uniform() * 1.8f + 0.1f, uniform() * 1.8f - 0.9f};
    const Vec3 direction = normalize(Vec3{uniform() - 0.5f, uniform() - 0.5f, uniform() - 0.5f});
    const Bvh4WalkHit a = bvh4_closest_hit<true>(scene.bvh.nodes.data(), scene.bvh.nodes.size(),
                                                 scene.bvh.leaf_triangles.data(), corners, origin, direction, 1e30f, stack);
    const Bvh4WalkHit b = bvh4_closest_hit<false>(scene.bvh.nodes.data(), scene.bvh.nodes.size(),
                                                  scene.bvh.leaf_triangles.data(), corners, origin, direction, 1e30f, stack);
    ASSERT_EQ(a.found, b.found) << "ray " << i;
    ASSERT_EQ(a.distance, b.distance) << "ray " << i;
  }
}

// --- A glTF camera node ----------------------------------------------------------------------------

TEST(ViewGltfCamera, ANodeCameraUnderATranslatedParentLooksWhereTheNodeLooks) {
  const fs::path dir = testing::fresh_temp_dir("view-camera");
  samples::SceneBuilder builder;
  samples::Material west, east;
  west.baseColor = {0.2f, 0.7f, 0.2f};
  east.baseColor = {0.2f, 0.2f, 0.7f};
  const auto west_id = builder.addMaterial(west), east_id = builder.addMaterial(east);
  add_floor(builder, west_id, east_id);
  builder.write((dir / "floor.gltf").string());
  // Add the camera: node "Rig" at y = 0.5 holding node "Eye" 0.5 higher, turned -90 degrees about X
  // (its -Z looks down -Y, its +Y becomes -Z); the camera "EyeCam" is 2:1.
  nlohmann::json gltf = nlohmann::json::parse(read_text(dir / "floor.gltf"));
  gltf["cameras"] = {{{"name", "EyeCam"}, {"type", "perspective"},
                      {"perspective", {{"yfov", 0.5}, {"aspectRatio", 2.0}, {"znear", 0.01}}}}};
  const size_t eye = gltf["nodes"].size(), rig = eye + 1;
  const double h = std::sqrt(0.5);
  gltf["nodes"].push_back({{"name", "Eye"}, {"camera", 0}, {"translation", {0, 0.5, 0}}, {"rotation", {-h, 0, 0, h}}});
  gltf["nodes"].push_back({{"name", "Rig"}, {"children", {eye}}, {"translation", {0, 0.5, 0}}});
  gltf["scenes"][0]["nodes"].push_back(rig);
  std::ofstream(dir / "floor.gltf") << gltf.dump();
  BakeOptions options = small_bake(dir / "floor.gltf", dir / "floor.bake");
  options.probes_enabled = false;
  Diagnostics diagnostics;
  run_bake(options, diagnostics);

  const view::ViewScene scene = view::open_view_scene((dir / "floor.bake").string());
  ASSERT_EQ(scene.scene.cameras.size(), 1u);
  const view::GltfCameraView by_camera = view::gltf_camera(scene.scene, "EyeCam");
  const view::GltfCameraView by_node = view::gltf_camera(scene.scene, "Eye");
  EXPECT_EQ(by_camera.aspect_ratio, 2.0f);
  const view::PinholeCamera expected = view::look_at_camera({0, 1, 0}, {0, 0, 0}, {0, 0, -1}, 0.5);
  for (const view::PinholeCamera& c : {by_camera.camera, by_node.camera}) {
    EXPECT_NEAR(c.eye.y, 1.0f, 1e-6f);
    EXPECT_NEAR(dot(c.forward, expected.forward), 1.0f, 1e-6f);
    EXPECT_NEAR(dot(c.right, expected.right), 1.0f, 1e-6f);
    EXPECT_NEAR(dot(c.up, expected.up), 1.0f, 1e-6f);
    EXPECT_NEAR(c.tan_half_yfov, std::tan(0.25), 1e-7);
  }
  // Image right is +X: the west (green) half on the left, the east (blue) half on the right.
  view::ViewRenderOptions render;
  render.width = 64;
  render.height = 32;
  render.mode = ViewMode::Albedo;
  const view::ViewImage image = view::render_view(scene, by_camera.camera, render);
  EXPECT_EQ(image.pixel(8, 16).y, 0.7f);
  EXPECT_EQ(image.pixel(56, 16).z, 0.7f);

  try {
    view::gltf_camera(scene.scene, "Nobody");
    ADD_FAILURE() << "an unknown camera was accepted";
  } catch (const view::ViewInputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"EyeCam\""), std::string::npos) << e.what();
  }
  // The binary: W alone takes the camera's aspect (64 -> 64 x 32).
  const std::string out = (dir / "eye.exr").string();
  ASSERT_EQ(run(std::string(EXITANCE_VIEW) + " " + (dir / "floor.bake").string() +
                " --camera EyeCam --size 64 --mode albedo -o " + out + " 2>/dev/null"),
            0);
  const formats::LightmapImage exr = formats::read_lightmap_exr(out);
  EXPECT_EQ(exr.width, 64);
  EXPECT_EQ(exr.height, 32);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace exitance
