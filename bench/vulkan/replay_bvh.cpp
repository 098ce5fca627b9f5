// Link-time stand-ins for bench_vulkan_replay (built by build_replay.sh), which links the Vulkan
// backend's sources without Embree: the GPU BVH comes from the replay file (built by Embree on the
// machine that wrote it), and LightmapEstimate's accessors are copied from
// runtime/src/cpu_reference_integrator.cpp, whose translation unit needs Embree and TBB.
#include <algorithm>
#include <stdexcept>

#include "exitance/runtime/cpu_reference_integrator.h"
#include "gpu_bvh.h"

namespace exitance {
namespace vulkan {

GpuBvh* g_replay_bvh = nullptr;  // set by replay_main.cpp before VulkanIntegrator::create

GpuBvh build_gpu_bvh(const Scene&) {
  if (!g_replay_bvh) throw std::runtime_error("bench_vulkan_replay: no BVH loaded");
  return *g_replay_bvh;
}

}  // namespace vulkan

Vec3 LightmapEstimate::mean_total(size_t texel) const {
  const TexelAccumulator& a = texels[texel];
  if (a.samples == 0) return {0, 0, 0};
  return {float(a.total[0] / a.samples), float(a.total[1] / a.samples), float(a.total[2] / a.samples)};
}

Vec3 LightmapEstimate::variance_of_mean(size_t texel) const {
  const TexelAccumulator& a = texels[texel];
  if (a.samples < 2) return {0, 0, 0};
  Vec3 v;
  for (int c = 0; c < 3; ++c) {
    const double n = a.samples;
    const double mean = a.total[c] / n;
    const double sample_variance = std::max(0.0, (a.total_squared[c] - n * mean * mean) / (n - 1));
    v[c] = float(sample_variance / n);
  }
  return v;
}

}  // namespace exitance
