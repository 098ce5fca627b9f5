// GPU-side figures of bench_vulkan_throughput: a timed bake, an
// instrumented bake (per-stage GPU time, rays, lane efficiency) and the traversal-only kernel.
#pragma once
#include <cstdio>

#include "exitance/runtime/vulkan/vulkan_integrator.h"

namespace exitance::bench {

inline void print_device_line(const VulkanIntegrator& vk) {
  std::printf("device: %s (%s); paths in flight %u; path state %zu B/path; BVH4 %u nodes, %.1f MB\n",
              vk.device().name.c_str(), to_string(vk.device().type), vk.max_paths(), vk.path_state_bytes_per_path(),
              vk.bvh_node_count(), double(vk.bvh_bytes()) / 1e6);
}

// Prints the stage table of an instrumented integrator's last bake (lightmap or probes: its wall
// seconds and rays), then runs the traversal-only kernel.
inline void print_stage_figures(const VulkanIntegrator& vk_stats, double bake_seconds, uint64_t bake_rays,
                                uint32_t traversal_rays, int traversal_repetitions) {
  std::printf("\n| stage | GPU s | items | rays | rays/s | lane efficiency |\n|---|---|---|---|---|---|\n");
  double gpu_total = 0;
  for (const VulkanStageStatistics& s : vk_stats.stage_statistics()) {
    gpu_total += s.seconds;
    std::printf("| %s | %.4f | %llu | %llu | %.3g | %.1f %% |\n", s.stage.c_str(), s.seconds, (unsigned long long)s.items,
                (unsigned long long)s.rays, s.seconds > 0 ? double(s.rays) / s.seconds : 0.0, 100.0 * s.lane_efficiency);
  }
  std::printf("instrumented total %.3f s wall, %.3f s GPU (sum of stages), %llu rays, %.3g rays/s of GPU time\n",
              bake_seconds, gpu_total, (unsigned long long)bake_rays, gpu_total > 0 ? double(bake_rays) / gpu_total : 0.0);
  if (traversal_rays == 0) return;
  const double traversal = vk_stats.measure_incoherent_traversal(traversal_rays, traversal_repetitions);
  for (const VulkanStageStatistics& s : vk_stats.stage_statistics())  // the traversal kernel's one stage
    if (s.stage.rfind("traversal", 0) == 0)
      std::printf("traversal-only: %u incoherent rays (%llu hit), %.3g rays/s, lane efficiency %.1f %%\n", traversal_rays,
                  (unsigned long long)s.items, traversal, 100.0 * s.lane_efficiency);
}

inline void print_stage_figures(const VulkanIntegrator& vk_stats, const LightmapEstimate& instrumented,
                                uint32_t traversal_rays, int traversal_repetitions) {
  print_stage_figures(vk_stats, instrumented.seconds, instrumented.rays, traversal_rays, traversal_repetitions);
}

}  // namespace exitance::bench
