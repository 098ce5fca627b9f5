// An engine's own Vulkan device for tests that hand one to the runtime (VulkanExternalDevice):
// an instance with the validation layer and a messenger whose messages fail the test, a device on
// a physical device with the features asked for, its first compute queue.
#pragma once
#include <gtest/gtest.h>

#include <vulkan/vulkan.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "exitance/runtime/vulkan/vulkan_integrator.h"

namespace exitance::testing {

// The engine's side: an instance with the validation layer and a messenger collecting messages,
// a device on the physical device `index` with `features`, its first compute queue.
class EngineDevice {
 public:
  EngineDevice(uint32_t index, VkPhysicalDeviceFeatures features) {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "engine";
    app.apiVersion = VK_API_VERSION_1_2;
    const char* layer = "VK_LAYER_KHRONOS_validation";
    const char* extension = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    VkDebugUtilsMessengerCreateInfoEXT messenger{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                            VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    messenger.pfnUserCallback = &EngineDevice::on_message;
    messenger.pUserData = &messages_;
    VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    info.pApplicationInfo = &app;
    info.enabledLayerCount = 1;
    info.ppEnabledLayerNames = &layer;
    info.enabledExtensionCount = 1;
    info.ppEnabledExtensionNames = &extension;
    info.pNext = &messenger;
    if (vkCreateInstance(&info, nullptr, &external_.instance) != VK_SUCCESS)
      throw std::runtime_error("engine: vkCreateInstance with the validation layer failed");
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(external_.instance, "vkCreateDebugUtilsMessengerEXT"));
    if (create(external_.instance, &messenger, nullptr, &messenger_) != VK_SUCCESS)
      throw std::runtime_error("engine: vkCreateDebugUtilsMessengerEXT failed");
    uint32_t count = 0;
    vkEnumeratePhysicalDevices(external_.instance, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(external_.instance, &count, devices.data());
    if (index >= count) throw std::runtime_error("engine: no physical device " + std::to_string(index));
    external_.physical_device = devices[index];
    vkGetPhysicalDeviceQueueFamilyProperties(external_.physical_device, &count, nullptr);
    std::vector<VkQueueFamilyProperties> families(count);
    vkGetPhysicalDeviceQueueFamilyProperties(external_.physical_device, &count, families.data());
    external_.queue_family = uint32_t(std::find_if(families.begin(), families.end(), [](const VkQueueFamilyProperties& f) {
                                        return (f.queueFlags & VK_QUEUE_COMPUTE_BIT) != 0;
                                      }) - families.begin());
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queue{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queue.queueFamilyIndex = external_.queue_family;
    queue.queueCount = 1;
    queue.pQueuePriorities = &priority;
    VkDeviceCreateInfo device{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    device.queueCreateInfoCount = 1;
    device.pQueueCreateInfos = &queue;
    device.pEnabledFeatures = &features;
    if (vkCreateDevice(external_.physical_device, &device, nullptr, &external_.device) != VK_SUCCESS)
      throw std::runtime_error("engine: vkCreateDevice failed");
    vkGetDeviceQueue(external_.device, external_.queue_family, 0, &external_.queue);
    external_.api_version = app.apiVersion;
    external_.enabled_features = features;
  }

  // The engine outlives the integrators it lent its device to, then destroys what it made.
  ~EngineDevice() {
    if (external_.device) vkDestroyDevice(external_.device, nullptr);
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(external_.instance, "vkDestroyDebugUtilsMessengerEXT"));
    if (messenger_) destroy(external_.instance, messenger_, nullptr);
    vkDestroyInstance(external_.instance, nullptr);
    for (const std::string& m : messages_) ADD_FAILURE() << m;
  }

  const VulkanExternalDevice& external() const { return external_; }
  VulkanDeviceOptions options() const {
    VulkanDeviceOptions options;
    options.external_device = external_;
    return options;
  }

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT, VkDebugUtilsMessageTypeFlagsEXT,
                                                   const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    static_cast<std::vector<std::string>*>(user)->push_back(std::string("[engine's validation] ") +
                                                           (data && data->pMessage ? data->pMessage : ""));
    return VK_FALSE;
  }

  VulkanExternalDevice external_;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  std::vector<std::string> messages_;
};

}  // namespace exitance::testing
