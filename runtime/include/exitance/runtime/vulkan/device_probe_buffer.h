// What the refreshed light probes show, as a device buffer an engine reads (the C API's
// exitance_runtime_publish_probes, exitance_runtime_vulkan.h).
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>

namespace exitance {

struct DeviceProbeBuffer {
  VkBuffer buffer = VK_NULL_HANDLE;  // 27 floats per probe of the grid (coefficient i, channel c at [i * 3 + c])
  VkDeviceSize size = 0;             // bytes: 108 per probe of the grid
  uint32_t probes = 0;               // the grid's probes (0 for probes not in use)
  VkSemaphore ready = VK_NULL_HANDLE;  // timeline semaphore (none on a device without them)
  uint64_t ready_value = 0;            // reached when the last write is done
  uint32_t queue_family = 0;           // the family it is written on (shared by every family: concurrent)
};

}  // namespace exitance
