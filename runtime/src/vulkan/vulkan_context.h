// Thin RAII layer over the Vulkan objects the wavefront needs: instance (+ validation messenger),
// one compute queue, buffers, compute pipelines, one-shot submissions with fence timeouts.
#pragma once
#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "exitance/runtime/vulkan/vulkan_integrator.h"

namespace exitance::vulkan {

std::string result_name(VkResult result);
// Throws std::runtime_error naming the call; device loss and out-of-memory get their own wording.
void check(VkResult result, const char* what);

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize size = 0;
  void* mapped = nullptr;  // host-visible buffers only
};

class Context {
 public:
  Context(const VulkanDeviceOptions& options);
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  const VulkanDeviceInfo& info() const { return info_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  const VkPhysicalDeviceMemoryProperties& memory_properties() const { return memory_properties_; }
  uint32_t subgroup_size() const { return subgroup_size_; }
  bool timestamps() const { return timestamp_valid_bits_ > 0; }

  Buffer create_buffer(VkDeviceSize size, VkBufferUsageFlags usage, bool host_visible);
  void destroy(Buffer& buffer);
  // Copies host data into a device buffer (through a staging buffer) and waits.
  void upload(const Buffer& dst, const void* data, VkDeviceSize size, VkDeviceSize offset = 0);
  void download(const Buffer& src, void* data, VkDeviceSize size, VkDeviceSize offset = 0);

  VkCommandBuffer begin();  // the context's single command buffer, reset
  // Submits the command buffer and waits for its fence; throws on timeout or device loss.
  void submit_and_wait(VkCommandBuffer cmd);
  bool lost() const { return lost_; }

 private:
  void cleanup();
  uint32_t find_memory_type(uint32_t bits, VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) const;

  VulkanDeviceOptions options_;
  struct Messages;
  std::unique_ptr<Messages> messages_;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_properties_{};
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  uint32_t subgroup_size_ = 0;
  uint32_t timestamp_valid_bits_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VulkanDeviceInfo info_;
  bool lost_ = false;
};

}  // namespace exitance::vulkan
