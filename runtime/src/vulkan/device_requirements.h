// What the wavefront kernels need from a Vulkan device (shaders/include/common.glsl's extensions):
// Vulkan 1.2, a compute queue, shaderInt64, shaderFloat64, subgroup basic/ballot/arithmetic
// operations in compute shaders. Checked when choosing a device and when adopting an engine's.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>

#include "exitance/runtime/vulkan/vulkan_integrator.h"

namespace exitance::vulkan {

// Name, type and whether the device can run the backend (missing_feature says why not).
// `queue_family`: the first family with compute; `subgroup_size`: the device's subgroup size.
VulkanDeviceInfo describe_device(VkPhysicalDevice physical, uint32_t index, uint32_t* queue_family = nullptr,
                                 uint32_t* subgroup_size = nullptr);

// Lower ranks first: a discrete GPU, an integrated one, a virtual one, a CPU device (lavapipe).
int preference_rank(VulkanDeviceType type);

// Throws std::runtime_error naming what an engine's device (or how it was created) lacks.
void check_adopted_device(const VulkanExternalDevice& external);

}  // namespace exitance::vulkan
