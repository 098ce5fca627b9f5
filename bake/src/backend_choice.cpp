#include "exitance/bake/backend_choice.h"

#include <tbb/info.h>

#include <mutex>
#include <stdexcept>

#include "exitance/runtime/vulkan/vulkan_integrator.h"

namespace exitance {
namespace {

struct ValidationMessages {
  std::mutex mutex;
  std::vector<std::string> lines;
};

LightingBackend cpu_backend(const Scene& scene) {
  auto integrator = std::make_shared<CpuReferenceIntegrator>(scene);
  LightingBackend backend;
  backend.name = "cpu";
  backend.device = "Embree 3 CPU reference on " + std::to_string(tbb::info::default_concurrency()) + " threads";
  backend.bake = [integrator](const TexelGBuffer& g, const IntegratorSettings& s) { return integrator->bake(g, s); };
  backend.bake_probes = [integrator](const std::vector<Vec3>& p, const IntegratorSettings& s) {
    return integrator->bake_probes(p, s);
  };
  backend.keep_alive = integrator;
  return backend;
}

LightingBackend vulkan_backend(const Scene& scene, const BackendRequest& request) {
  VulkanDeviceOptions options;
  options.device_index = request.device_index;
  options.validation = request.validation;
  // Messages arrive on a driver callback: collect them there, fail the bake afterwards.
  auto messages = std::make_shared<ValidationMessages>();
  if (request.validation)
    options.on_validation_message = [messages](const std::string& message) {
      std::lock_guard<std::mutex> lock(messages->mutex);
      messages->lines.push_back(message);
    };
  std::shared_ptr<VulkanIntegrator> integrator = VulkanIntegrator::create(scene, options);
  LightingBackend backend;
  backend.name = "vulkan";
  backend.device = integrator->device().name + " (" + to_string(integrator->device().type) + ")";
  backend.bake = [integrator, messages](const TexelGBuffer& g, const IntegratorSettings& s) {
    LightmapEstimate estimate = integrator->bake(g, s);
    std::lock_guard<std::mutex> lock(messages->mutex);
    if (!messages->lines.empty())
      throw std::runtime_error("Vulkan validation reported " + std::to_string(messages->lines.size()) +
                               " messages, first: " + messages->lines.front());
    return estimate;
  };
  backend.bake_probes = [integrator, messages](const std::vector<Vec3>& positions, const IntegratorSettings& s) {
    ProbeEstimate estimate = integrator->bake_probes(positions, s);
    std::lock_guard<std::mutex> lock(messages->mutex);
    if (!messages->lines.empty())
      throw std::runtime_error("Vulkan validation reported " + std::to_string(messages->lines.size()) +
                               " messages, first: " + messages->lines.front());
    return estimate;
  };
  backend.keep_alive = integrator;
  return backend;
}

bool is_gpu(const VulkanDeviceInfo& device) {
  return device.usable && (device.type == VulkanDeviceType::Discrete || device.type == VulkanDeviceType::Integrated ||
                           device.type == VulkanDeviceType::Virtual);
}

}  // namespace

LightingBackend choose_lighting_backend(const Scene& scene, const BackendRequest& request, Diagnostics& diagnostics) {
  if (request.name == "cpu") return cpu_backend(scene);
  if (request.name == "vulkan") return vulkan_backend(scene, request);

  const std::vector<VulkanDeviceInfo> devices = enumerate_vulkan_devices();
  bool has_gpu = false;
  for (const VulkanDeviceInfo& d : devices)
    if (is_gpu(d) && (request.device_index < 0 || int(d.index) == request.device_index)) has_gpu = true;
  if (!has_gpu) {
    diagnostics.warn(devices.empty()
                         ? "--backend auto: no Vulkan device; using the CPU reference (Embree)"
                         : "--backend auto: only a CPU Vulkan device (lavapipe measured 0.1-0.2x Embree's rays/s on 2 cores, "
                           "bench/results/vulkan-lavapipe.md); "
                           "using the CPU reference (Embree)");
    return cpu_backend(scene);
  }
  try {
    return vulkan_backend(scene, request);
  } catch (const std::exception& e) {
    diagnostics.warn(std::string("--backend auto: Vulkan backend unavailable for this scene (") + e.what() +
                     "); using the CPU reference (Embree)");
    return cpu_backend(scene);
  }
}

}  // namespace exitance
