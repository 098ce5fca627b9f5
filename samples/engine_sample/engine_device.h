// The engine's own Vulkan instance and device, which it lends to the Exitance runtime: Vulkan 1.2,
// one queue family with graphics and compute, the features the runtime needs (shaderInt64,
// shaderFloat64, timeline semaphores), and a VK_EXT_debug_utils messenger when the extension is
// there (validation layers are enabled from the environment, e.g.
// VK_INSTANCE_LAYERS=VK_LAYER_KHRONOS_validation), counting validation errors.
#pragma once
#include <vulkan/vulkan.h>

#include <stdexcept>
#include <string>

#include "exitance/runtime/exitance_runtime_vulkan.h"

namespace engine_sample {

// Throws std::runtime_error naming the call and its VkResult.
void check_vk(VkResult result, const char* call);

// Validation errors the messenger heard so far, about the sample's calls or the runtime's; counted
// outside EngineDevice so that what the layer reports while the device and instance are destroyed
// (objects left alive) counts too.
uint32_t validation_errors();

class EngineDevice {
 public:
  EngineDevice();
  ~EngineDevice();
  EngineDevice(const EngineDevice&) = delete;
  EngineDevice& operator=(const EngineDevice&) = delete;

  // What exitance_runtime_open_on_device adopts.
  ExitanceRuntimeVulkanDevice runtime_device() const;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physical_device() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queue_family() const { return family_; }
  const std::string& name() const { return name_; }
  bool messenger_installed() const { return messenger_ != VK_NULL_HANDLE; }

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                   VkDebugUtilsMessageTypeFlagsEXT types,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);

  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t family_ = 0;
  VkPhysicalDeviceFeatures enabled_{};
  std::string name_;
};

}  // namespace engine_sample
