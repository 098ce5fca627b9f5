// Rays per second of the Vulkan wavefront against the Embree CPU reference on one scene, measured in
// one run (DESIGN §7: ratios on the shared machine, absolute figures only on the GPU machine), plus
// per-stage figures and a traversal-only kernel's incoherent rays/s.
//
//   bench_vulkan_throughput SCENE.gltf [--sky R,G,B] [--texel-density T] [--spp N] [--cpu-spp N]
//                           [--max-paths N] [--traversal-rays N] [--skip-cpu] [--write-replay FILE]
//                           [--node-layout auto|float|quantized]
//
// --write-replay FILE: writes the scene, the live texels and the GPU BVH (bench/vulkan/replay_format.h)
// and exits; bench_vulkan_replay (bench/vulkan/build_replay.sh) then runs the GPU half of this bench
// on a machine that has nothing but a Vulkan driver.
#include <CLI/CLI.hpp>

#include <cstdio>

#include "exitance/bake/prepared_scene.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "../../runtime/src/vulkan/gpu_bvh.h"
#include "reference_comparison.h"
#include "replay_format.h"
#include "report.h"

using namespace exitance;

int main(int argc, char** argv) {
  std::string scene_path, sky, replay_path, node_layout = "auto";
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
  app.add_option("--write-replay", replay_path, "write a replay file for bench_vulkan_replay and exit");
  std::string reference_path;
  app.add_option("--write-reference", reference_path,
                 "with --write-replay: also bake the CPU reference at --cpu-spp (seed 7) and write it for "
                 "bench_vulkan_replay --reference");
  CLI11_PARSE(app, argc, argv);

  Diagnostics diagnostics;
  AtlasSettings atlas;
  atlas.texel_density = density;
  const PreparedScene prepared = prepare_scene_for_lighting(scene_path, sky, atlas, diagnostics);
  const Scene& scene = prepared.scene;
  const TexelGBuffer& gbuffer = prepared.gbuffer;
  std::printf("scene %s: %zu triangles, %zu live texels, %u spp\n", scene_path.c_str(), scene.triangle_count(),
              gbuffer.texels.size(), spp);

  if (!replay_path.empty()) {
    const vulkan::GpuBvh bvh = vulkan::build_gpu_bvh(scene);
    replay::write_replay(replay_path, {scene_path, density}, scene, gbuffer, bvh);
    std::printf("wrote %s (BVH4 %zu nodes, stack bound %u)\n", replay_path.c_str(), bvh.nodes.size(), bvh.stack_entries);
    if (!reference_path.empty()) {
      IntegratorSettings reference_settings;
      reference_settings.spp = cpu_spp ? cpu_spp : spp;
      reference_settings.seed = 7;  // independent of the replay's seed 1
      const LightmapEstimate reference = CpuReferenceIntegrator(scene).bake(gbuffer, reference_settings);
      replay::write_reference(reference_path, reference);
      std::printf("wrote %s (CPU reference, %u spp, %.1f s)\n", reference_path.c_str(), reference_settings.spp,
                  reference.seconds);
    }
    return 0;
  }

  VulkanDeviceOptions options;
  options.max_paths = max_paths;
  options.node_layout = node_layout == "float"       ? VulkanNodeLayout::Float
                        : node_layout == "quantized" ? VulkanNodeLayout::Quantized
                                                     : VulkanNodeLayout::Automatic;
  auto vk = VulkanIntegrator::create(scene, options);
  bench::print_device_line(*vk);
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
  auto vk_stats = VulkanIntegrator::create(scene, options);
  settings.spp = spp;
  const LightmapEstimate instrumented = vk_stats->bake(gbuffer, settings);
  bench::print_stage_figures(*vk_stats, instrumented, traversal_rays, 3);
  return 0;
}
