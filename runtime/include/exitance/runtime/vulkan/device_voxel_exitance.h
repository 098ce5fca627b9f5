// The voxel exitance of what the runtime shows, as a device buffer an engine reads (the C API's
// exitance_runtime_publish_voxel_exitance, exitance_runtime_vulkan.h).
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>

namespace exitance {

struct DeviceVoxelExitance {
  VkBuffer buffer = VK_NULL_HANDLE;  // 6 floats per node of svo.bin, in its order: front RGB, back RGB (M = pi L_o)
  VkDeviceSize size = 0;             // bytes: 24 per node
  uint32_t nodes = 0;
  VkSemaphore ready = VK_NULL_HANDLE;  // timeline semaphore (none on a device without them)
  uint64_t ready_value = 0;            // reached when the last write is done
  uint32_t queue_family = 0;           // the family it is written on (shared by every family: concurrent)
};

}  // namespace exitance
