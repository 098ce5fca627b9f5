// Path-traced view time (bench/results/view.md): the camera-ray batch of a bundle's view lit by the
// CPU reference (Embree) or the Vulkan backend (a GPU, or lavapipe on a CPU-only machine).
// bench_path_traced_view BUNDLE --backend cpu|vulkan [--size N] [--spp N] [--runs N] + the camera.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/view/path_traced_view.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"

int main(int argc, char** argv) {
  using namespace exitance;
  CLI::App app{"path-traced view time"};
  std::string bundle, backend = "cpu";
  int size = 256, runs = 3;
  uint32_t spp = 64;
  std::vector<float> from{0, 2, 1.9f}, at{0, 1.7f, -2};
  double yfov = 1.1;
  app.add_option("bundle", bundle)->required();
  app.add_option("--backend", backend)->check(CLI::IsMember({"cpu", "vulkan"}));
  app.add_option("--size", size);
  app.add_option("--spp", spp);
  app.add_option("--runs", runs);
  app.add_option("--look-from", from)->expected(3)->delimiter(',');
  app.add_option("--look-at", at)->expected(3)->delimiter(',');
  app.add_option("--yfov", yfov);
  CLI11_PARSE(app, argc, argv);

  const view::ViewScene scene = view::open_view_scene(bundle);
  const view::PinholeCamera camera = view::look_at_camera({from[0], from[1], from[2]}, {at[0], at[1], at[2]}, {0, 1, 0}, yfov);
  const std::shared_ptr<const LightingScene> lighting = view::lighting_scene_of(scene);
  std::unique_ptr<Integrator> integrator;
  if (backend == "cpu")
    integrator = std::make_unique<CpuReferenceIntegrator>(*lighting->source);
  else
    integrator = VulkanIntegrator::create(lighting);
  std::printf("backend %s (%s), %d x %d, %u spp\n", backend.c_str(), integrator->device_description().c_str(), size, size, spp);
  for (int run = 0; run < runs; ++run) {
    IntegratorSettings settings;
    settings.spp = spp;
    settings.seed = uint64_t(run);
    settings.recorded_bounces = 1;
    const auto start = std::chrono::steady_clock::now();
    const view::PathTracedView v = view::render_path_traced_view(scene, camera, size, size, *integrator, settings);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("run %d: %.3f s (lighting %.3f s), %zu hit pixels, %.1f M rays, %.2f M rays/s\n", run, seconds,
                v.estimate.seconds, v.estimate.texels.size(), double(v.estimate.rays) * 1e-6,
                double(v.estimate.rays) * 1e-6 / seconds);
  }
  return 0;
}
