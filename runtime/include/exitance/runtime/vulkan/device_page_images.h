// The published lightmap as device images an engine samples (the C API's
// exitance_runtime_publish_page_images, exitance_runtime_vulkan.h).
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

namespace exitance {

struct DevicePageImage {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;  // 2D, the whole image
  uint32_t width = 0, height = 0;
};

struct DevicePageImages {
  std::vector<DevicePageImage> pages;  // one per atlas page, in page order
  VkFormat format = VK_FORMAT_R32G32B32A32_SFLOAT;  // E/pi in RGB, coverage in A
  VkImageLayout layout = VK_IMAGE_LAYOUT_GENERAL;   // always
  VkSemaphore ready = VK_NULL_HANDLE;  // timeline semaphore (none on a device without them)
  uint64_t ready_value = 0;            // reached when the last write is done
  uint32_t queue_family = 0;           // the family they are written on (shared by every family: concurrent)
};

}  // namespace exitance
