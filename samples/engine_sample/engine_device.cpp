#include "engine_device.h"

#include <atomic>
#include <cstdio>
#include <cstring>
#include <vector>

namespace engine_sample {
namespace {

std::atomic<uint32_t> g_validation_errors{0};

bool at_least_1_2(uint32_t version) {
  return VK_API_VERSION_MAJOR(version) > 1 ||
         (VK_API_VERSION_MAJOR(version) == 1 && VK_API_VERSION_MINOR(version) >= 2);
}

bool instance_has_extension(const char* name) {
  uint32_t count = 0;
  vkEnumerateInstanceExtensionProperties(nullptr, &count, nullptr);
  std::vector<VkExtensionProperties> extensions(count);
  vkEnumerateInstanceExtensionProperties(nullptr, &count, extensions.data());
  for (const VkExtensionProperties& e : extensions)
    if (std::strcmp(e.extensionName, name) == 0) return true;
  return false;
}

int type_rank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;  // lavapipe
    default: return 4;
  }
}

// The first queue family with graphics and compute (the runtime submits its compute work to the
// engine's queue), or -1; else why the device cannot be used, in `missing`.
int usable_family(VkPhysicalDevice physical, std::string& missing) {
  VkPhysicalDeviceProperties properties;
  vkGetPhysicalDeviceProperties(physical, &properties);
  VkPhysicalDeviceVulkan12Features features12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &features12};
  if (at_least_1_2(properties.apiVersion)) vkGetPhysicalDeviceFeatures2(physical, &features);
  uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(physical, &count, families.data());
  int family = -1;
  const VkQueueFlags needed = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
  for (uint32_t i = 0; i < count && family < 0; ++i)
    if ((families[i].queueFlags & needed) == needed) family = int(i);
  if (!at_least_1_2(properties.apiVersion))
    missing = "Vulkan 1.2";
  else if (family < 0)
    missing = "a graphics and compute queue family";
  else if (!features.features.shaderInt64)
    missing = "shaderInt64";
  else if (!features.features.shaderFloat64)
    missing = "shaderFloat64";
  else if (!features12.timelineSemaphore)
    missing = "timelineSemaphore";
  return missing.empty() ? family : -1;
}

}  // namespace

uint32_t validation_errors() { return g_validation_errors.load(); }

void check_vk(VkResult result, const char* call) {
  if (result != VK_SUCCESS)
    throw std::runtime_error(std::string(call) + " failed (VkResult " + std::to_string(int(result)) + ")");
}

EngineDevice::EngineDevice() {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "exitance_engine_sample";
  app.apiVersion = VK_API_VERSION_1_2;  // the runtime's kernels need 1.2 (ExitanceRuntimeVulkanDevice::api_version)
  // The program enables no layer itself; with a validation layer enabled from the environment, the
  // messenger makes its errors fail the run. Passed in pNext too, to hear about vkCreateInstance.
  VkDebugUtilsMessengerCreateInfoEXT messenger{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  messenger.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messenger.pfnUserCallback = &EngineDevice::on_message;
  const bool debug_utils = instance_has_extension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  const char* extension = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  if (debug_utils) {
    info.pNext = &messenger;
    info.enabledExtensionCount = 1;
    info.ppEnabledExtensionNames = &extension;
  }
  check_vk(vkCreateInstance(&info, nullptr, &instance_), "vkCreateInstance");
  if (debug_utils) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
    if (create) check_vk(create(instance_, &messenger, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
  }

  // A discrete GPU if there is one, else any usable device (an integrated GPU, lavapipe).
  uint32_t count = 0;
  vkEnumeratePhysicalDevices(instance_, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  vkEnumeratePhysicalDevices(instance_, &count, devices.data());
  std::string rejected;
  int best_rank = 1 << 30;
  for (VkPhysicalDevice physical : devices) {
    VkPhysicalDeviceProperties properties;
    vkGetPhysicalDeviceProperties(physical, &properties);
    std::string missing;
    const int family = usable_family(physical, missing);
    if (family < 0) {
      rejected += std::string(rejected.empty() ? "" : "; ") + properties.deviceName + " lacks " + missing;
      continue;
    }
    if (type_rank(properties.deviceType) < best_rank) {
      best_rank = type_rank(properties.deviceType);
      physical_ = physical;
      family_ = uint32_t(family);
      name_ = properties.deviceName;
    }
  }
  if (!physical_)
    throw std::runtime_error("no usable Vulkan device (" + (rejected.empty() ? std::string("none found") : rejected) +
                             ")");

  // What the runtime needs (exitance_runtime_vulkan.h), and nothing the sample's shaders do not use.
  enabled_.shaderInt64 = VK_TRUE;
  enabled_.shaderFloat64 = VK_TRUE;
  VkPhysicalDeviceVulkan12Features features12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  features12.timelineSemaphore = VK_TRUE;
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue.queueFamilyIndex = family_;
  queue.queueCount = 1;
  queue.pQueuePriorities = &priority;
  VkDeviceCreateInfo device{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &features12};
  device.queueCreateInfoCount = 1;
  device.pQueueCreateInfos = &queue;
  device.pEnabledFeatures = &enabled_;
  check_vk(vkCreateDevice(physical_, &device, nullptr, &device_), "vkCreateDevice");
  vkGetDeviceQueue(device_, family_, 0, &queue_);
}

EngineDevice::~EngineDevice() {
  if (device_) vkDestroyDevice(device_, nullptr);
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
}

ExitanceRuntimeVulkanDevice EngineDevice::runtime_device() const {
  ExitanceRuntimeVulkanDevice d{};
  d.instance = instance_;
  d.physical_device = physical_;
  d.device = device_;
  d.queue = queue_;
  d.queue_family = family_;
  d.api_version = VK_API_VERSION_1_2;
  d.enabled_features = enabled_;
  d.timeline_semaphore = 1;
  return d;
}

VKAPI_ATTR VkBool32 VKAPI_CALL EngineDevice::on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                        VkDebugUtilsMessageTypeFlagsEXT types,
                                                        const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                        void* /*user*/) {
  const bool error = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) != 0;
  // Validation errors fail the run; the loader's own messages and warnings are only shown.
  if (error && (types & VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT)) g_validation_errors += 1;
  std::fprintf(stderr, "exitance_engine_sample: vulkan %s: %s\n", error ? "error" : "warning",
               data && data->pMessage ? data->pMessage : "");
  return VK_FALSE;
}

}  // namespace engine_sample
