// Rays per second of the Vulkan wavefront against the Embree CPU reference on one scene, measured in
// one run (DESIGN §7: ratios on the shared machine, absolute figures only on the GPU machine), plus
// per-stage figures and a traversal-only kernel's incoherent rays/s.
//
//   bench_vulkan_throughput SCENE.gltf [--sky R,G,B] [--texel-density T] [--spp N] [--cpu-spp N]
//                           [--max-paths N] [--traversal-rays N] [--skip-cpu]
//                           [--node-layout auto|float|quantized] [--probes NX,NY,NZ [--probe-spp N]]
//
// --probes NX,NY,NZ: light probes instead of the lightmap: an NX x NY x NZ grid of probes at the
// cell centres of the scene's bounds, --probe-spp rays each (default 256), on both backends (same
// settings, seed 1): probe rays/s (every ray: probe rays, bounces and shadow rays) and the ratio,
// then the stage table of an instrumented probe bake (stage "rays: primary" = the probe rays).
//
// On the GPU machine the same figures come from exitance-relight --stage-statistics on a bundle baked
// here (bench/results/relight-gpu.md).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <sstream>

#include "exitance/bake/command/prepared_scene.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "exitance/runtime/cpu/bvh4_builder.h"
#include "exitance/runtime/cpu_reference_integrator.h"
#include "report.h"

using namespace exitance;

int main(int argc, char** argv) {
  std::string scene_path, sky, node_layout = "auto";
  float density = 4;
  uint32_t spp = 16, cpu_spp = 0, max_paths = 0, traversal_rays = 1u << 22;
  bool skip_cpu = false;
  CLI::App app{"Vulkan wavefront vs Embree reference throughput"};
  app.add_option("scene", scene_path)->required();
  app.add_option("--sky", sky);
  app.add_option("--texel-density", density);
  app.add_option("--spp", spp);
  app.add_option("--cpu-spp", cpu_spp, "spp of the CPU run (default: same)");
  app.add_option("--max-paths", max_paths);
  app.add_option("--traversal-rays", traversal_rays);
  app.add_flag("--skip-cpu", skip_cpu);
  app.add_option("--node-layout", node_layout, "BVH4 node layout: auto, float or quantized")
      ->check(CLI::IsMember({"auto", "float", "quantized"}));
  std::string probe_grid;
  uint32_t probe_spp = 256;
  app.add_option("--probes", probe_grid, "NX,NY,NZ: bake a probe grid over the scene bounds instead of the lightmap");
  app.add_option("--probe-spp", probe_spp, "rays per probe with --probes");
  CLI11_PARSE(app, argc, argv);
  uint32_t grid[3] = {0, 0, 0};
  if (!probe_grid.empty()) {
    std::istringstream in(probe_grid);
    char comma = 0;
    in >> grid[0] >> comma >> grid[1] >> comma >> grid[2];
    if (!in || grid[0] == 0 || grid[1] == 0 || grid[2] == 0) {
      std::fprintf(stderr, "--probes wants NX,NY,NZ (positive integers)\n");
      return 2;
    }
  }

  Diagnostics diagnostics;
  AtlasSettings atlas;
  atlas.texel_density = density;
  const PreparedScene prepared = prepare_scene_for_lighting(scene_path, sky, atlas, diagnostics);
  const Scene& scene = prepared.scene;
  const TexelGBuffer& gbuffer = prepared.gbuffer;
  std::printf("scene %s: %zu triangles, %zu live texels, %u spp\n", scene_path.c_str(), scene.triangle_count(),
              gbuffer.texels.size(), spp);

  VulkanDeviceOptions options;
  options.max_paths = max_paths;
  options.node_layout = node_layout == "float"       ? VulkanNodeLayout::Float
                        : node_layout == "quantized" ? VulkanNodeLayout::Quantized
                                                     : VulkanNodeLayout::Automatic;
  auto vk = VulkanIntegrator::create(make_lighting_scene(scene), options);
  bench::print_device_line(*vk);
  if (grid[0] > 0) {
    Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
    for (const Vec3& p : scene.positions) lo = min(lo, p), hi = max(hi, p);
    std::vector<Vec3> probes;
    for (uint32_t z = 0; z < grid[2]; ++z)
      for (uint32_t y = 0; y < grid[1]; ++y)
        for (uint32_t x = 0; x < grid[0]; ++x) {
          const Vec3 t{(float(x) + 0.5f) / float(grid[0]), (float(y) + 0.5f) / float(grid[1]), (float(z) + 0.5f) / float(grid[2])};
          probes.push_back(lo + (hi - lo) * t);
        }
    IntegratorSettings settings;
    settings.spp = probe_spp;
    settings.seed = 1;
    std::printf("probes: %ux%ux%u grid over (%.2f, %.2f, %.2f)..(%.2f, %.2f, %.2f), %u spp\n", grid[0], grid[1], grid[2],
                lo.x, lo.y, lo.z, hi.x, hi.y, hi.z, probe_spp);
    {
      IntegratorSettings warm = settings;  // lavapipe compiles pipelines at the first dispatch
      warm.spp = 1;
      vk->bake_probes(probes, warm);
    }
    const ProbeEstimate gpu = vk->bake_probes(probes, settings);
    const double gpu_rate = double(gpu.rays) / gpu.seconds;
    uint64_t back_faces = 0;
    for (uint32_t b : gpu.backface_hits) back_faces += b;
    std::printf("vulkan probes: %.3f s, %llu rays, %.3g rays/s, %.3g probe samples/s, back-face hits %.1f %%\n",
                gpu.seconds, (unsigned long long)gpu.rays, gpu_rate, double(probes.size()) * probe_spp / gpu.seconds,
                100.0 * double(back_faces) / (double(probes.size()) * probe_spp));
    if (!skip_cpu) {
      const ProbeEstimate cpu = CpuReferenceIntegrator(scene).bake_probes(probes, settings);
      const double cpu_rate = double(cpu.rays) / cpu.seconds;
      std::printf("embree reference probes: %.3f s, %llu rays, %.3g rays/s, %.3g probe samples/s\n", cpu.seconds,
                  (unsigned long long)cpu.rays, cpu_rate, double(probes.size()) * probe_spp / cpu.seconds);
      std::printf("ratio vulkan / embree probe rays/s: %.3f\n", gpu_rate / cpu_rate);
    }
    options.collect_stage_statistics = true;  // stage figures: a second, instrumented run
    auto vk_stats = VulkanIntegrator::create(make_lighting_scene(scene), options);
    const ProbeEstimate instrumented = vk_stats->bake_probes(probes, settings);
    bench::print_stage_figures(*vk_stats, instrumented.seconds, instrumented.rays, traversal_rays, 3);
    return 0;
  }
  IntegratorSettings settings;
  settings.spp = spp;
  settings.seed = 1;
  {
    // Warm-up: lavapipe compiles pipelines at the first dispatch; first-touch of buffers.
    IntegratorSettings warm = settings;
    warm.spp = 1;
    vk->bake(gbuffer, warm);
  }
  const LightmapEstimate gpu = vk->bake(gbuffer, settings);
  const double gpu_rate = double(gpu.rays) / gpu.seconds;
  std::printf("vulkan: %.3f s, %llu rays, %.3g rays/s\n", gpu.seconds, (unsigned long long)gpu.rays, gpu_rate);
  if (!skip_cpu) {
    settings.spp = cpu_spp ? cpu_spp : spp;
    const LightmapEstimate cpu = CpuReferenceIntegrator(scene).bake(gbuffer, settings);
    const double cpu_rate = double(cpu.rays) / cpu.seconds;
    std::printf("embree reference: %.3f s, %llu rays, %.3g rays/s\n", cpu.seconds, (unsigned long long)cpu.rays, cpu_rate);
    std::printf("ratio vulkan / embree rays/s: %.3f\n", gpu_rate / cpu_rate);
  }

  // Stage figures (timestamps + lane counters; a second, instrumented run).
  options.collect_stage_statistics = true;
  auto vk_stats = VulkanIntegrator::create(make_lighting_scene(scene), options);
  settings.spp = spp;
  const LightmapEstimate instrumented = vk_stats->bake(gbuffer, settings);
  bench::print_stage_figures(*vk_stats, instrumented, traversal_rays, 3);
  return 0;
}
