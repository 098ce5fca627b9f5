// A device buffer the runtime writes and an engine reads (the probe buffer, the voxel exitance):
// device-local, shared by every queue family of the device (VK_SHARING_MODE_CONCURRENT: no
// ownership transfer), with a timeline semaphore of its own that each write signals (none on a
// device without timeline semaphores), as the page images have.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "vulkan_context.h"

namespace exitance::vulkan {

class SharedDeviceBuffer {
 public:
  // `what` names it in errors ("probes").
  SharedDeviceBuffer(Context& context, VkDeviceSize bytes, const char* what);
  ~SharedDeviceBuffer();
  SharedDeviceBuffer(const SharedDeviceBuffer&) = delete;
  SharedDeviceBuffer& operator=(const SharedDeviceBuffer&) = delete;

  VkBuffer buffer() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  VkSemaphore ready() const { return ready_; }
  uint64_t ready_value() const { return ready_value_; }
  // Ends `cmd` (the compute write) with the barrier that makes it visible to any later read, submits
  // it, signals the semaphore to the next value and waits for it (bounded).
  void submit_write(VkCommandBuffer cmd);
  std::vector<float> read_back() const;  // a copy through staging, for tests and tools

 private:
  void release();
  Context& context_;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  VkSemaphore ready_ = VK_NULL_HANDLE;
  uint64_t ready_value_ = 0;
};

}  // namespace exitance::vulkan
