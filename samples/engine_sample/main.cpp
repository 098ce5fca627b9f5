// exitance_engine_sample: a headless "engine" using the Exitance runtime the way a renderer would.
// It creates its own Vulkan device and lends it to the runtime (exitance_runtime_open_on_device),
// loads the scene's geometry from the glTF itself, draws it with a graphics pipeline that samples the
// runtime's lightmap pages as Vulkan images (exitance_runtime_publish_page_images: no host read-back
// of the lightmap), and moves a light over the frames. Links only libexitance_runtime, the loader,
// the Vulkan loader, tinygltf and stb (DESIGN §2).
//
//   exitance_engine_sample room.gltf room.bake Lamp -1,3,0 1,3,0 --look-from 0,2,3.9 --look-at 0,1.5,0
//       --yfov 1.2 --size 320,240 --frames 4 -o strip.png
//
// Frame 0 shows the bundle's baked lightmap (nothing edited, nothing refreshed); frame k of N moves
// the light's node to FROM + (TO - FROM) k/(N-1), refreshes, and draws. --help says more.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "engine_device.h"
#include "engine_options.h"
#include "exitance/loader/exitance_loader.h"
#include "exitance/runtime/exitance_runtime.h"
#include "exitance/runtime/exitance_runtime_vulkan.h"
#include "gltf_geometry.h"
#include "lightmap_renderer.h"
#include "pinhole_camera.h"
#include "png_strip.h"
#include "stopwatch.h"

namespace engine_sample {
namespace {

// A frame that takes longer is a hung device, not a slow one (lavapipe draws these in milliseconds).
constexpr double kFrameTimeoutSeconds = 20.0;

// The runtime refused a call: its one-line message (which names the call), and the exit status
// (2 for a bad bundle or edit).
class RuntimeFailure : public std::runtime_error {
 public:
  RuntimeFailure(const std::string& call, ExitanceRuntimeError error)
      : std::runtime_error(message(call)), status(error) {}
  int exit_status() const {
    return status == EXITANCE_RUNTIME_BAD_BUNDLE || status == EXITANCE_RUNTIME_BAD_EDIT ? 2 : 1;
  }
  ExitanceRuntimeError status;

 private:
  static std::string message(const std::string& call) {
    const std::string text = exitance_runtime_last_error_message();
    return text.empty() ? call + " failed" : text;
  }
};

void check_runtime(ExitanceRuntimeError result, const char* call) {
  if (result != EXITANCE_RUNTIME_OK) throw RuntimeFailure(call, result);
}

struct BundleRelease {
  void operator()(ExitanceBundle* b) const { exitance_bundle_release(b); }
};
struct RuntimeRelease {
  void operator()(ExitanceRuntime* r) const { exitance_runtime_release(r); }
};

std::string point_text(const std::array<double, 3>& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.3f, %.3f, %.3f)", p[0], p[1], p[2]);
  return text;
}

int run(const EngineOptions& options) {
  const std::filesystem::path folder = std::filesystem::path(options.output).parent_path();
  std::error_code ec;
  if (!folder.empty() && !std::filesystem::is_directory(folder, ec))
    throw UsageError("-o: " + options.output + ": folder " + folder.string() + " does not exist");

  ExitanceBundle* opened = nullptr;
  if (exitance_bundle_open(options.bundle.c_str(), &opened) != EXITANCE_ERROR_NONE)
    throw UsageError("BUNDLE: " + std::string(exitance_last_error_message()));
  const std::unique_ptr<ExitanceBundle, BundleRelease> bundle(opened);
  const SceneGeometry scene = load_scene_geometry(options.gltf, bundle.get(), options.light);
  if (scene.lightmapped_instances == 0)
    throw UsageError(options.gltf + ": no mesh node matches an instance of " + options.bundle +
                     " (was it baked from this file?)");
  const std::array<float, 16> camera =
      view_projection(options.look_from, options.look_at, options.up, options.yfov, options.width, options.height);

  // Declared first, destroyed last: the runtime and the renderer use the device until they go.
  EngineDevice device;
  std::printf("device: %s (queue family %u); validation messages %s\n", device.name().c_str(), device.queue_family(),
              device.messenger_installed() ? "checked (VK_EXT_debug_utils)" : "not checked (no VK_EXT_debug_utils)");
  const ExitanceRuntimeVulkanDevice lent = device.runtime_device();
  ExitanceRuntime* created = nullptr;
  check_runtime(exitance_runtime_open_on_device(options.bundle.c_str(), nullptr, &lent, &created),
                "exitance_runtime_open_on_device");
  std::unique_ptr<ExitanceRuntime, RuntimeRelease> runtime(created);
  std::vector<ExitanceRuntimePageImage> pages(exitance_runtime_page_count(runtime.get()));
  std::printf("scene: %zu draws, %zu lightmapped instances on %zu pages, %zu without a lightmap (emission only)\n",
              scene.draws.size(), scene.lightmapped_instances, pages.size(), scene.unlit_instances);

  PngStrip strip(options.width, options.height, options.frames, options.exposure);
  std::unique_ptr<LightmapRenderer> renderer;
  for (uint32_t f = 0; f < options.frames; ++f) {
    std::string what;
    if (f == 0) {
      // No edit and no refresh: the runtime publishes the bundle's baked lightmap as it is.
      what = "baked lightmap, light node at " + point_text(scene.light.world_position);
    } else {
      const double t = options.frames > 1 ? double(f) / double(options.frames - 1) : 0.0;
      std::array<double, 3> at{};
      for (int c = 0; c < 3; ++c)
        at[size_t(c)] = options.from[size_t(c)] + (options.to[size_t(c)] - options.from[size_t(c)]) * t;
      // A light is moved through the node placing it (docs/edits.md: a light edit changes colour,
      // intensity and cone angles; a node edit moves everything the node places).
      char edits[256];
      std::snprintf(edits, sizeof edits, "{\"edits\": [{\"node\": %d, \"translation\": [%.9g, %.9g, %.9g]}]}",
                    scene.light.node, at[0], at[1], at[2]);
      check_runtime(exitance_runtime_apply_edits(runtime.get(), edits), "exitance_runtime_apply_edits");
      ExitanceRefreshReport report{};
      check_runtime(exitance_runtime_refresh(runtime.get(), 0.0, options.samples, &report), "exitance_runtime_refresh");
      char text[256];
      std::snprintf(text, sizeof text, "light node at %s (t = %.3f), %u samples per texel refreshed in %.1f ms",
                    point_text(at).c_str(), t, report.samples_per_texel, report.milliseconds);
      what = text;
    }
    ExitanceRuntimeImagesReady ready{};
    const Stopwatch publish_clock;
    check_runtime(exitance_runtime_publish_page_images(runtime.get(), pages.data(), uint32_t(pages.size()), &ready),
                  "exitance_runtime_publish_page_images");
    const double publish_ms = publish_clock.milliseconds();
    if (!renderer)
      renderer = std::make_unique<LightmapRenderer>(device, scene, options.width, options.height, pages);
    else
      renderer->set_pages(pages);
    const Stopwatch draw_clock;
    strip.put_frame(f, renderer->render(camera, ready, kFrameTimeoutSeconds));
    std::printf("frame %u: %s; pages published in %.1f ms, drawn in %.1f ms\n", f, what.c_str(), publish_ms,
                draw_clock.milliseconds());
    std::fflush(stdout);
  }
  strip.write(options.output);
  if (renderer && renderer->manual_bilinear())
    std::printf("note: the device cannot filter the pages linearly; the shader did\n");
  renderer.reset();
  runtime.reset();
  return 0;
}

}  // namespace
}  // namespace engine_sample

int main(int argc, char** argv) {
  using namespace engine_sample;
  EngineOptions options;
  int status = 0;
  try {
    if (!parse_engine_options(argc, argv, options)) {
      std::printf("%s\n\n%s", kUsage, kHelp);
      return 0;
    }
    status = run(options);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "exitance_engine_sample: error: %s (see --help)\n", e.what());
    status = 2;
  } catch (const RuntimeFailure& e) {
    std::fprintf(stderr, "exitance_engine_sample: %s\n", e.what());
    status = e.exit_status();
  } catch (const FrameTimeout& e) {
    // The device may still be using every resource: leave without destroying any.
    std::fprintf(stderr, "exitance_engine_sample: %s\n", e.what());
    std::fflush(nullptr);
    std::_Exit(1);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "exitance_engine_sample: %s\n", e.what());
    status = 1;
  }
  // Everything Vulkan is destroyed by now, so objects left alive have been reported too.
  if (validation_errors() > 0) {
    std::fprintf(stderr, "exitance_engine_sample: %u Vulkan validation errors\n", validation_errors());
    if (status == 0) status = 1;
  }
  return status;
}
