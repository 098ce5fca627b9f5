// bench_vulkan_replay: the GPU half of bench_vulkan_throughput, from a replay file written by
// `bench_vulkan_throughput SCENE --write-replay FILE` (bench/vulkan/replay_format.h). Needs only
// the Vulkan loader and a driver, so it runs on the GPU machine (build: bench/vulkan/build_replay.sh).
//
//   bench_vulkan_replay FILE [--spp N] [--max-paths N] [--traversal-rays N] [--iterations-per-submit N]
//                       [--work-per-path N] [--node-layout auto|float|quantized] [--skip-instrumented]
//                       [--reference FILE]   (cross-check against a CPU reference written by
//                                             bench_vulkan_throughput --write-reference; exit 3 on |z| >= 4)
//                       [--probes NX,NY,NZ [--probe-spp N]]  (also bake a probe grid at the centres of
//                                             NX x NY x NZ cells of the scene bounds; probe rays/s)
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "reference_comparison.h"
#include "replay_format.h"
#include "report.h"

using namespace exitance;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s FILE [--spp N] [--max-paths N] [--traversal-rays N] [--iterations-per-submit N] "
                 "[--work-per-path N] [--node-layout auto|float|quantized] [--skip-instrumented]\n",
                 argv[0]);
    return 2;
  }
  std::string path = argv[1];
  uint32_t spp = 256, max_paths = 0, traversal_rays = 1u << 24, iterations = 0, work_per_path = 0;
  bool skip_instrumented = false;
  std::string reference_path;
  uint32_t probe_counts[3] = {0, 0, 0}, probe_spp = 256;
  VulkanNodeLayout layout = VulkanNodeLayout::Automatic;
  for (int i = 2; i < argc; ++i) {
    auto next = [&]() -> uint32_t {
      if (i + 1 >= argc) { std::fprintf(stderr, "missing value after %s\n", argv[i]); std::exit(2); }
      return uint32_t(std::strtoul(argv[++i], nullptr, 10));
    };
    if (!std::strcmp(argv[i], "--spp")) spp = next();
    else if (!std::strcmp(argv[i], "--max-paths")) max_paths = next();
    else if (!std::strcmp(argv[i], "--traversal-rays")) traversal_rays = next();
    else if (!std::strcmp(argv[i], "--iterations-per-submit")) iterations = next();
    else if (!std::strcmp(argv[i], "--work-per-path")) work_per_path = next();
    else if (!std::strcmp(argv[i], "--node-layout") && i + 1 < argc) {
      const std::string v = argv[++i];
      layout = v == "float" ? VulkanNodeLayout::Float : v == "quantized" ? VulkanNodeLayout::Quantized : VulkanNodeLayout::Automatic;
    }
    else if (!std::strcmp(argv[i], "--skip-instrumented")) skip_instrumented = true;
    else if (!std::strcmp(argv[i], "--reference") && i + 1 < argc) reference_path = argv[++i];
    else if (!std::strcmp(argv[i], "--probes") && i + 1 < argc) {
      if (std::sscanf(argv[++i], "%u,%u,%u", &probe_counts[0], &probe_counts[1], &probe_counts[2]) != 3) return 2;
    }
    else if (!std::strcmp(argv[i], "--probe-spp")) probe_spp = next();
    else { std::fprintf(stderr, "unknown option %s\n", argv[i]); return 2; }
  }
  try {
    replay::ReplayInfo info;
    Scene scene;
    TexelGBuffer gbuffer;
    Bvh4 bvh;
    replay::read_replay(path, info, scene, gbuffer, bvh);
    const auto lighting = std::make_shared<const LightingScene>(
        build_lighting_scene(std::make_shared<const Scene>(scene), std::move(bvh)));
    std::printf("scene %s (replay %s): %zu triangles, %zu live texels at density %g, %u spp\n", info.scene_name.c_str(),
                path.c_str(), scene.triangle_count(), gbuffer.texels.size(), double(info.texel_density), spp);
    VulkanDeviceOptions options;
    options.max_paths = max_paths;
    options.iterations_per_submit = iterations;
    options.work_items_per_path = work_per_path;
    options.node_layout = layout;
    options.fence_timeout_seconds = 60;
    IntegratorSettings settings;
    settings.seed = 1;
    {
      auto vk = VulkanIntegrator::create(lighting, options);
      bench::print_device_line(*vk);
      IntegratorSettings warm = settings;
      warm.spp = 1;
      vk->bake(gbuffer, warm);
      settings.spp = spp;
      const LightmapEstimate gpu = vk->bake(gbuffer, settings);
      std::printf("vulkan bake: %.3f s, %llu rays, %.3g rays/s end to end (%llu non-finite samples)\n", gpu.seconds,
                  (unsigned long long)gpu.rays, double(gpu.rays) / gpu.seconds, (unsigned long long)gpu.nonfinite_samples);
      double mean = 0;
      for (size_t i = 0; i < gpu.texels.size(); ++i) mean += luminance(gpu.mean_total(i));
      std::printf("mean texel luminance (E/pi) %.6g\n", gbuffer.texels.empty() ? 0.0 : mean / double(gpu.texels.size()));
      if (probe_counts[0] * probe_counts[1] * probe_counts[2] > 0) {
        Vec3 lo = scene.positions.front(), hi = lo;
        for (const Vec3& p : scene.positions)
          for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
        std::vector<Vec3> probes;
        for (uint32_t z = 0; z < probe_counts[2]; ++z)
          for (uint32_t y = 0; y < probe_counts[1]; ++y)
            for (uint32_t x = 0; x < probe_counts[0]; ++x) {
              const uint32_t c[3] = {x, y, z};
              Vec3 p;
              for (int a = 0; a < 3; ++a) p[a] = lo[a] + (hi[a] - lo[a]) * (float(c[a]) + 0.5f) / float(probe_counts[a]);
              probes.push_back(p);
            }
        IntegratorSettings probe_settings = settings;
        probe_settings.spp = 1;
        vk->bake_probes(probes, probe_settings);  // warm-up
        probe_settings.spp = probe_spp;
        const ProbeEstimate e = vk->bake_probes(probes, probe_settings);
        std::printf("vulkan probes: %zu probes x %u spp: %.3f s, %llu rays, %.3g rays/s end to end (%llu non-finite)\n",
                    probes.size(), probe_spp, e.seconds, (unsigned long long)e.rays, double(e.rays) / e.seconds,
                    (unsigned long long)e.nonfinite_samples);
      }
      if (!reference_path.empty()) {
        const replay::ReferenceComparison c = replay::compare_with_reference(reference_path, gpu, 32);
        std::printf("cross-check vs CPU reference: %zu regions x 3 channels, max |z| %.2f, relMSE %.3g "
                    "(noise alone %.3g)\n", c.regions, c.max_abs_z, c.rel_mse, c.noise_rel_mse);
        if (!(c.max_abs_z < 4.0) || !(c.rel_mse < 0.005)) {
          std::fprintf(stderr, "bench_vulkan_replay: cross-check FAILED\n");
          return 3;
        }
        if (skip_instrumented && traversal_rays == 0) return 0;
      }
    }
    options.collect_stage_statistics = true;
    auto vk_stats = VulkanIntegrator::create(lighting, options);
    LightmapEstimate instrumented;
    if (!skip_instrumented) instrumented = vk_stats->bake(gbuffer, settings);
    bench::print_stage_figures(*vk_stats, instrumented, traversal_rays, 5);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_vulkan_replay: %s\n", e.what());
    return 1;
  }
  return 0;
}
