#include "exitance/bake/command/backend_choice.h"

#include <stdexcept>

#include "exitance/runtime/cpu_reference_integrator.h"
#include "exitance/runtime/vulkan/validation_messages.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"

namespace exitance {
namespace {

// The Vulkan backend with validation layers on: any message fails the bake that produced it.
class ValidationCheckedIntegrator final : public Integrator {
 public:
  ValidationCheckedIntegrator(std::shared_ptr<const Integrator> inner, std::shared_ptr<ValidationMessages> messages)
      : inner_(std::move(inner)), messages_(std::move(messages)) {}
  std::string backend_name() const override { return inner_->backend_name(); }
  std::string device_description() const override { return inner_->device_description(); }
  LightmapEstimate bake(const TexelGBuffer& g, const IntegratorSettings& s) const override {
    LightmapEstimate estimate = inner_->bake(g, s);
    check();
    return estimate;
  }
  ProbeEstimate bake_probes(const std::vector<Vec3>& p, const IntegratorSettings& s) const override {
    ProbeEstimate estimate = inner_->bake_probes(p, s);
    check();
    return estimate;
  }

 private:
  void check() const { messages_->throw_if_any(); }
  std::shared_ptr<const Integrator> inner_;
  std::shared_ptr<ValidationMessages> messages_;
};

std::shared_ptr<const Integrator> vulkan_backend(std::shared_ptr<const LightingScene> scene,
                                                 const BackendRequest& request) {
  VulkanDeviceOptions options;
  options.device_index = request.device_index;
  options.validation = request.validation;
  auto messages = std::make_shared<ValidationMessages>();
  if (request.validation) options.on_validation_message = ValidationMessages::collector(messages);
  std::shared_ptr<const Integrator> integrator = VulkanIntegrator::create(std::move(scene), options);
  if (!request.validation) return integrator;
  return std::make_shared<ValidationCheckedIntegrator>(std::move(integrator), messages);
}

bool is_gpu(const VulkanDeviceInfo& device) {
  return device.usable && (device.type == VulkanDeviceType::Discrete || device.type == VulkanDeviceType::Integrated ||
                           device.type == VulkanDeviceType::Virtual);
}

}  // namespace

std::shared_ptr<const Integrator> choose_lighting_backend(std::shared_ptr<const LightingScene> scene,
                                                          std::shared_ptr<const EmbreeScene> embree,
                                                          const BackendRequest& request, Diagnostics& diagnostics) {
  auto cpu = [&] { return std::make_shared<const CpuReferenceIntegrator>(scene, embree); };
  if (request.name == "cpu") return cpu();
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
    return cpu();
  }
  try {
    return vulkan_backend(scene, request);
  } catch (const std::exception& e) {
    diagnostics.warn(std::string("--backend auto: Vulkan backend unavailable for this scene (") + e.what() +
                     "); using the CPU reference (Embree)");
    return cpu();
  }
}

std::string backend_candidates(const BackendRequest& request) {
  if (request.name == "cpu") return "cpu";
  std::string devices = request.name;
  for (const VulkanDeviceInfo& d : enumerate_vulkan_devices())
    devices += ";" + std::to_string(d.index) + ":" + d.name + ":" + to_string(d.type) + ":" +
               std::to_string(d.api_version) + ":" + (d.usable ? "usable" : "unusable");
  return devices;
}

}  // namespace exitance
