// Picks the lighting backend for `bake --backend auto|vulkan|cpu` and runs it.
#pragma once
#include <functional>
#include <memory>
#include <string>

#include "exitance/bake/diagnostics.h"
#include "exitance/runtime/cpu_reference_integrator.h"

namespace exitance {

struct BackendRequest {
  std::string name = "auto";  // auto | vulkan | cpu
  int device_index = -1;      // --device N; -1 = prefer a discrete GPU
  bool validation = false;    // EXITANCE_VULKAN_VALIDATION=1: validation layers, any message is an error
};

// A ready backend: what it is and how to run it.
struct LightingBackend {
  std::string name;    // "cpu" or "vulkan"
  std::string device;  // human-readable device ("Embree 3 on N threads", GPU name)
  std::function<LightmapEstimate(const TexelGBuffer&, const IntegratorSettings&)> bake;
  // Light probes, on the same backend and device as the lightmaps.
  std::function<ProbeEstimate(const std::vector<Vec3>&, const IntegratorSettings&)> bake_probes;
  std::shared_ptr<void> keep_alive;  // owns the integrator
};

// auto: a GPU Vulkan device when one exists and supports the scene; otherwise the CPU reference,
// because on this project's 2-core CPU machines lavapipe measured 0.1-0.2x Embree's rays/s
// (bench/results/vulkan-lavapipe.md). Notices go to `diagnostics`. Throws std::runtime_error
// when `vulkan` is requested and impossible.
LightingBackend choose_lighting_backend(const Scene& scene, const BackendRequest& request, Diagnostics& diagnostics);

}  // namespace exitance
