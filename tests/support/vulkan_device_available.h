// Whether this machine has a Vulkan device the backend can use (lavapipe counts): tests that need
// one skip without it.
#pragma once
#include "exitance/runtime/vulkan/vulkan_integrator.h"

namespace exitance::testing {

inline bool has_vulkan_device() {
  for (const VulkanDeviceInfo& d : enumerate_vulkan_devices())
    if (d.usable) return true;
  return false;
}

}  // namespace exitance::testing
