// An engine's Vulkan device, adopted by the Vulkan backend instead of one of its own (DESIGN §1:
// the runtime re-lights "on the engine's device or its own").
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>

namespace exitance {

// The engine keeps these alive until the integrator is destroyed; the backend creates no instance
// or device and destroys none of them. It still creates and destroys its own command pool, fence,
// buffers, pipelines, descriptor and query pools on `device`, and submits to `queue`, which the
// engine must not use from another thread during a bake or an update (vkQueueSubmit needs the
// queue externally synchronised). Validation is the engine's too: its instance's layers and
// messenger see the backend's calls.
struct VulkanExternalDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;  // queue of `queue_family`, which must support compute
  uint32_t queue_family = 0;
  // VkApplicationInfo::apiVersion the instance was created with: the kernels are SPIR-V for
  // Vulkan 1.2, so 1.2 or later (Vulkan offers no query for it).
  uint32_t api_version = 0;
  // The features `device` was created with (VkDeviceCreateInfo::pEnabledFeatures, or
  // VkPhysicalDeviceFeatures2::features): at least those of vulkan_required_features().
  VkPhysicalDeviceFeatures enabled_features{};
  // Whether the device was created with VkPhysicalDeviceVulkan12Features::timelineSemaphore: then
  // the lightmap page images an engine samples come with a timeline semaphore to wait on.
  bool timeline_semaphore = false;
};

// What a device must be created with for the backend: shaderInt64 and shaderFloat64 (the kernels'
// random number generator and double-precision light CDFs). Subgroup basic, ballot and arithmetic
// operations in compute shaders, and Vulkan 1.2, must be supported too (core, nothing to enable).
VkPhysicalDeviceFeatures vulkan_required_features();

}  // namespace exitance
