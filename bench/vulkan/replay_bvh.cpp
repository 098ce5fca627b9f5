// Link-time stand-ins for bench_vulkan_replay (built by build_replay.sh), which links the Vulkan
// backend's sources without Embree: the GPU BVH comes from the replay file (built by Embree on the
// machine that wrote it). LightmapEstimate's accessors come from runtime/src/lightmap_estimate.cpp.
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

}  // namespace exitance
