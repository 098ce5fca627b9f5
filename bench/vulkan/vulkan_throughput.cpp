// Rays per second of the Vulkan wavefront against the Embree CPU reference on one scene, measured in
// one run (DESIGN §7: ratios on the shared machine, absolute figures only on the GPU machine), plus
// per-stage figures and a traversal-only kernel's incoherent rays/s.
//
//   bench_vulkan_throughput SCENE.gltf [--sky R,G,B] [--texel-density T] [--spp N] [--cpu-spp N]
//                           [--max-paths N] [--traversal-rays N] [--skip-cpu]
#include <CLI/CLI.hpp>

#include <cstdio>

#include "exitance/bake/atlas_layout.h"
#include "exitance/bake/bake_pipeline.h"
#include "exitance/bake/gltf_import.h"
#include "exitance/bake/texel_raster.h"
#include "exitance/bake/unocclude.h"
#include "exitance/runtime/embree_scene.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"

using namespace exitance;

int main(int argc, char** argv) {
  std::string scene_path, sky;
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
  CLI11_PARSE(app, argc, argv);

  Diagnostics diagnostics;
  Scene scene = import_gltf(scene_path, {}, diagnostics);
  scene.sky = parse_sky_option(sky);
  AtlasSettings atlas;
  atlas.texel_density = density;
  const AtlasLayout layout = layout_lightmap_atlas(scene, atlas, scene_path, diagnostics);
  TexelGBuffer gbuffer = rasterize_texel_gbuffer(scene, layout, scene_path, diagnostics);
  {
    EmbreeScene embree(scene);
    unocclude_texels(embree, gbuffer);
  }
  std::printf("scene %s: %zu triangles, %zu live texels, %u spp\n", scene_path.c_str(), scene.triangle_count(),
              gbuffer.texels.size(), spp);

  VulkanDeviceOptions options;
  options.max_paths = max_paths;
  auto vk = VulkanIntegrator::create(scene, options);
  std::printf("device: %s (%s); paths in flight %u; path state %zu B/path; BVH4 %u nodes, %.1f MB\n",
              vk->device().name.c_str(), to_string(vk->device().type), vk->max_paths(), vk->path_state_bytes_per_path(),
              vk->bvh_node_count(), double(vk->bvh_bytes()) / 1e6);
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
  std::printf("\n| stage | GPU s | items | rays | rays/s | lane efficiency |\n|---|---|---|---|---|---|\n");
  for (const VulkanStageStatistics& s : vk_stats->stage_statistics())
    std::printf("| %s | %.4f | %llu | %llu | %.3g | %.1f %% |\n", s.stage.c_str(), s.seconds, (unsigned long long)s.items,
                (unsigned long long)s.rays, s.seconds > 0 ? double(s.rays) / s.seconds : 0.0, 100.0 * s.lane_efficiency);
  std::printf("instrumented total %.3f s\n", instrumented.seconds);
  const double traversal = vk_stats->measure_incoherent_traversal(traversal_rays, 3);
  for (const VulkanStageStatistics& s : vk_stats->stage_statistics())
    if (s.stage == "traversal-only")
      std::printf("traversal-only: %u incoherent rays, %.3g rays/s, lane efficiency %.1f %%\n", traversal_rays, traversal,
                  100.0 * s.lane_efficiency);
  return 0;
}
