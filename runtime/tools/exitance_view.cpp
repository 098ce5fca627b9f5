// exitance-view BUNDLE (--look-from X,Y,Z --look-at X,Y,Z --yfov RADIANS [--up X,Y,Z] | --camera NAME)
//               [--size W[,H]] [--aa N] [--mode lightmap|probes|albedo|normal|error] [--exposure EV]
//               [--path-traced [--spp N] [--seed N]] -o FILE.exr|FILE.png
// Renders a view of a baked bundle as an engine would draw it from the baked data (docs/view.md), on
// the CPU, or with --path-traced the reference view lit by the runtime's Vulkan backend. No Embree:
// the baked view needs the loader and formats; the path-traced one a Vulkan device (GPU or lavapipe).
#include <CLI/CLI.hpp>

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "exitance/runtime/view/path_traced_view.h"
#include "exitance/runtime/view/view_camera.h"
#include "exitance/runtime/view/view_image_output.h"
#include "exitance/runtime/view/view_input_error.h"
#include "exitance/runtime/view/view_render.h"
#include "exitance/runtime/view/view_scene.h"
#include "exitance/runtime/tools/command_line_errors.h"

namespace {

using exitance::one_line;
using exitance::Vec3;
using exitance::view::ViewInputError;

constexpr int kMaxImageSide = 16384;
constexpr int kMaxSamplesPerAxis = 16;

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> parts{""};
  for (char c : text) {
    if (c == ',')
      parts.emplace_back();
    else
      parts.back() += c;
  }
  return parts;
}

// A whole-string finite number; std::nullopt for anything else ("1x", "", "nan", "inf").
std::optional<double> parse_number(const std::string& text) {
  double value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || ptr != end || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::optional<int> parse_integer(const std::string& text) {
  int value = 0;
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (ec != std::errc() || ptr != end) return std::nullopt;
  return value;
}

Vec3 parse_vector(const std::string& option, const std::string& text) {
  const std::vector<std::string> parts = split_commas(text);
  if (parts.size() == 3) {
    const auto x = parse_number(parts[0]), y = parse_number(parts[1]), z = parse_number(parts[2]);
    if (x && y && z) return {float(*x), float(*y), float(*z)};
  }
  throw ViewInputError(option + ": \"" + text + "\" is not X,Y,Z (three finite numbers separated by commas)");
}

double parse_scalar(const std::string& option, const std::string& text) {
  const auto value = parse_number(text);
  if (!value) throw ViewInputError(option + ": \"" + text + "\" is not a finite number");
  return *value;
}

int parse_side(const std::string& text, const std::string& whole) {
  const auto value = parse_integer(text);
  if (!value) throw ViewInputError("--size: \"" + whole + "\" is not W or W,H (whole numbers of pixels)");
  if (*value < 1 || *value > kMaxImageSide)
    throw ViewInputError("--size: " + text + " pixels is not within 1 .. " + std::to_string(kMaxImageSide));
  return *value;
}

struct ImageSize {
  int width = 512;
  std::optional<int> height;  // absent: from the camera's aspect ratio, else square
};

ImageSize parse_size(const std::string& text) {
  const std::vector<std::string> parts = split_commas(text);
  if (parts.size() == 1) return {parse_side(parts[0], text), std::nullopt};
  if (parts.size() == 2) return {parse_side(parts[0], text), parse_side(parts[1], text)};
  throw ViewInputError("--size: \"" + text + "\" is not W or W,H (whole numbers of pixels)");
}

struct CommandLine {
  std::string bundle, output, camera, mode = "lightmap";
  std::optional<std::string> look_from, look_at, up, yfov, size, aa, exposure, spp, seed;
  unsigned threads = 0;
  bool path_traced = false;
};

struct ViewRequest {
  exitance::view::ViewRenderOptions render;
  ImageSize size;
  float exposure_ev = 0;
  uint32_t path_traced_spp = 0;  // 0: the baked view
  uint64_t seed = 0;
};

constexpr int kMaxPathTracedSpp = 1 << 20;

// Every check that needs no file, in the order of the synopsis.
ViewRequest check_options(const CommandLine& cl) {
  ViewRequest request;
  if (!cl.camera.empty()) {
    for (const auto& [option, value] : {std::pair{"--look-from", cl.look_from}, std::pair{"--look-at", cl.look_at},
                                        std::pair{"--yfov", cl.yfov}, std::pair{"--up", cl.up}})
      if (value) throw ViewInputError(std::string(option) + ": cannot be combined with --camera");
  } else {
    for (const auto& [option, value] :
         {std::pair{"--look-from", cl.look_from}, std::pair{"--look-at", cl.look_at}, std::pair{"--yfov", cl.yfov}})
      if (!value) throw ViewInputError(std::string(option) + ": is required (or --camera NAME)");
  }
  if (cl.size) request.size = parse_size(*cl.size);
  if (cl.aa) {
    const auto aa = parse_integer(*cl.aa);
    if (!aa || *aa < 1 || *aa > kMaxSamplesPerAxis)
      throw ViewInputError("--aa: \"" + *cl.aa + "\" is not a whole number within 1 .. " + std::to_string(kMaxSamplesPerAxis));
    request.render.samples_per_axis = *aa;
  }
  const auto mode = exitance::view::parse_view_mode(cl.mode);
  if (!mode) throw ViewInputError("--mode: \"" + cl.mode + "\" is not one of lightmap, probes, albedo, normal, error");
  request.render.mode = *mode;
  if (cl.exposure) request.exposure_ev = float(parse_scalar("--exposure", *cl.exposure));
  request.render.threads = cl.threads;
  if (cl.path_traced) {
    // The reference view: one ray per pixel centre, the lighting it shows is path traced.
    if (cl.aa) throw ViewInputError("--aa: cannot be combined with --path-traced (one ray through each pixel centre)");
    if (request.render.mode != exitance::view::ViewMode::Lightmap)
      throw ViewInputError("--mode: " + cl.mode + " cannot be combined with --path-traced (it shows the lit view)");
    const auto spp = parse_integer(cl.spp.value_or("64"));
    if (!spp || *spp < 1 || *spp > kMaxPathTracedSpp)
      throw ViewInputError("--spp: \"" + *cl.spp + "\" is not a whole number within 1 .. " + std::to_string(kMaxPathTracedSpp));
    request.path_traced_spp = uint32_t(*spp);
    if (cl.seed) {
      const auto seed = parse_integer(*cl.seed);
      if (!seed || *seed < 0) throw ViewInputError("--seed: \"" + *cl.seed + "\" is not a whole number >= 0");
      request.seed = uint64_t(*seed);
    }
  } else {
    if (cl.spp) throw ViewInputError("--spp: needs --path-traced");
    if (cl.seed) throw ViewInputError("--seed: needs --path-traced");
  }
  exitance::view::view_image_format(cl.output);
  return request;
}

exitance::view::PinholeCamera option_camera(const CommandLine& cl) {
  const Vec3 from = parse_vector("--look-from", *cl.look_from), at = parse_vector("--look-at", *cl.look_at);
  const Vec3 up = cl.up ? parse_vector("--up", *cl.up) : Vec3{0, 1, 0};
  return exitance::view::look_at_camera(from, at, up, parse_scalar("--yfov", *cl.yfov));
}

// What the bundle must hold for the mode; a warning where the view will be partly unlit.
void check_bundle_for_mode(const exitance::view::ViewScene& view, exitance::view::ViewMode mode, const std::string& bundle) {
  using exitance::view::ViewMode;
  if (mode == ViewMode::Error && !view.bundle.has_lightmap_channel(exitance::view::kErrorChannel))
    throw ViewInputError(bundle + ": the lightmap has no " + exitance::view::kErrorChannel +
                         " layer (--mode error needs a bake that writes per-texel error)");
  if (mode == ViewMode::Probes && !view.bundle.has_probes())
    throw ViewInputError(bundle + ": has no probes (baked with --probes none); --mode probes needs them");
  if (mode == ViewMode::Lightmap && !view.bundle.has_probes())
    for (uint8_t has_texels : view.instance_has_texels)
      if (!has_texels) {
        std::cerr << "exitance-view: warning: " << bundle
                  << ": instances without lightmap texels stay unlit (the bundle has no probes)\n";
        break;
      }
}

// --path-traced: the camera-ray batch lit by the runtime's Vulkan backend (a GPU, else lavapipe).
exitance::view::ViewImage path_traced_image(const exitance::view::ViewScene& view, const exitance::view::PinholeCamera& camera,
                                            const ViewRequest& request) {
  const auto integrator = exitance::VulkanIntegrator::create(exitance::view::lighting_scene_of(view));
  exitance::IntegratorSettings settings;
  settings.spp = request.path_traced_spp;
  settings.seed = request.seed;
  settings.recorded_bounces = 1;
  return exitance::view::render_path_traced_view(view, camera, request.render.width, request.render.height, *integrator, settings)
      .image;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"exitance-view: render a view of a baked bundle from its baked data, on the CPU"};
  CommandLine cl;
  app.add_option("bundle", cl.bundle, "the bundle folder bake wrote (manifest.json, lightmaps, probes.bin, scene.bin)")
      ->required();
  app.add_option("--look-from", cl.look_from, "camera position X,Y,Z");
  app.add_option("--look-at", cl.look_at, "point the camera looks at X,Y,Z");
  app.add_option("--up", cl.up, "up direction X,Y,Z (default 0,1,0)");
  app.add_option("--yfov", cl.yfov, "vertical field of view in radians, in (0, pi)");
  app.add_option("--camera", cl.camera, "a glTF camera (or its node) recorded in scene.bin, instead of --look-*");
  app.add_option("--size", cl.size, "image size W or W,H in pixels (default 512; W alone: the camera's aspect, else square)");
  app.add_option("--aa", cl.aa, "N x N stratified rays per pixel, N in 1..16 (default 1: the pixel centre)");
  app.add_option("--mode", cl.mode, "lightmap (default) | probes | albedo | normal | error");
  app.add_option("--exposure", cl.exposure, "PNG only: multiply by 2^EV before the tone curve (default 0)");
  app.add_flag("--path-traced", cl.path_traced, "path trace the lighting at each pixel's first hit (Vulkan) instead of reading the bundle");
  app.add_option("--spp", cl.spp, "--path-traced: paths per pixel, 1..1048576 (default 64)");
  app.add_option("--seed", cl.seed, "--path-traced: random seed (default 0)");
  app.add_option("--threads", cl.threads, "render threads (default: one per hardware thread)");
  app.add_option("-o,--out", cl.output, "output image: FILE.exr (linear) or FILE.png (tone-mapped, sRGB)")->required();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return exitance::exit_for_option_error(app, e, "exitance-view");
  }
  try {
    using Clock = std::chrono::steady_clock;
    ViewRequest request = check_options(cl);
    std::optional<exitance::view::PinholeCamera> camera;
    if (cl.camera.empty()) camera = option_camera(cl);
    exitance::view::check_view_output_writable(cl.output);

    const auto opened = Clock::now();
    const exitance::view::ViewScene view = exitance::view::open_view_scene(cl.bundle);
    check_bundle_for_mode(view, request.render.mode, cl.bundle);
    float camera_aspect = 0;
    if (!camera) {
      const exitance::view::GltfCameraView gltf = exitance::view::gltf_camera(view.scene, cl.camera);
      camera = gltf.camera;
      camera_aspect = gltf.aspect_ratio;
    }
    request.render.width = request.size.width;
    request.render.height = request.size.height ? *request.size.height
                            : camera_aspect > 0
                                ? std::clamp(int(std::lround(request.size.width / camera_aspect)), 1, kMaxImageSide)
                                : request.size.width;
    const auto rendering = Clock::now();
    const exitance::view::ViewImage image =
        request.path_traced_spp ? path_traced_image(view, *camera, request) : exitance::view::render_view(view, *camera, request.render);
    const auto writing = Clock::now();
    exitance::view::write_view_image(cl.output, image, request.exposure_ev);
    const auto seconds = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
    const std::string what = request.path_traced_spp
                                 ? "1 ray per pixel, path traced at " + std::to_string(request.path_traced_spp) + " spp"
                                 : std::to_string(request.render.samples_per_axis * request.render.samples_per_axis) +
                                       " ray(s) per pixel, " + exitance::view::view_mode_name(request.render.mode);
    std::fprintf(stderr, "exitance-view: wrote %s (%d x %d, %s; open %.3f s, render %.3f s, write %.3f s)\n",
                 cl.output.c_str(), image.width, image.height, what.c_str(), seconds(opened, rendering),
                 seconds(rendering, writing), seconds(writing, Clock::now()));
    return 0;
  } catch (const ViewInputError& e) {
    std::cerr << "exitance-view: error: " << one_line(e.what()) << "\n";
    return 2;
  } catch (const exitance::VulkanDeviceFailure& e) {  // --path-traced; see exitance_relight.cpp
    std::cerr << "exitance-view: error: " << cl.bundle << ": device failure while path tracing: " << one_line(e.what()) << "\n";
    std::fflush(stderr);
    std::_Exit(exitance::kDeviceFailureExitCode);
  } catch (const std::exception& e) {
    std::cerr << "exitance-view: error: " << cl.bundle << ": " << one_line(e.what()) << "\n";
    return 1;
  }
}
