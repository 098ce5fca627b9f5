#include "shared_device_buffer.h"

#include <cstring>
#include <string>
#include <utility>

namespace exitance::vulkan {

SharedDeviceBuffer::SharedDeviceBuffer(Context& context, VkDeviceSize bytes, const char* what) : context_(context), size_(bytes) {
  VkDevice d = context.device();
  try {
    uint32_t family_count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(context.physical_device(), &family_count, nullptr);
    std::vector<uint32_t> families(family_count);
    for (uint32_t f = 0; f < family_count; ++f) families[f] = f;
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = bytes;
    info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    info.sharingMode = family_count > 1 ? VK_SHARING_MODE_CONCURRENT : VK_SHARING_MODE_EXCLUSIVE;
    if (family_count > 1) info.queueFamilyIndexCount = family_count, info.pQueueFamilyIndices = families.data();
    check(vkCreateBuffer(d, &info, nullptr, &buffer_), ("vkCreateBuffer (" + std::string(what) + ")").c_str());
    VkMemoryRequirements requirements;
    vkGetBufferMemoryRequirements(d, buffer_, &requirements);
    memory_ = context.allocate_device_local(requirements, ("allocating the " + std::string(what) + " buffer").c_str());
    check(vkBindBufferMemory(d, buffer_, memory_, 0), ("vkBindBufferMemory (" + std::string(what) + ")").c_str());
    if (context.timeline_semaphores()) {
      VkSemaphoreTypeCreateInfo type{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
      type.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
      VkSemaphoreCreateInfo semaphore{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
      semaphore.pNext = &type;
      check(vkCreateSemaphore(d, &semaphore, nullptr, &ready_), ("vkCreateSemaphore (" + std::string(what) + " ready)").c_str());
    }
  } catch (...) {
    release();
    throw;
  }
}

SharedDeviceBuffer::~SharedDeviceBuffer() { release(); }

void SharedDeviceBuffer::release() {
  if (context_.hung()) return;  // a running submission may still use them (Context::cleanup)
  VkDevice d = context_.device();
  if (buffer_) vkDestroyBuffer(d, std::exchange(buffer_, VK_NULL_HANDLE), nullptr);
  if (memory_) vkFreeMemory(d, std::exchange(memory_, VK_NULL_HANDLE), nullptr);
  if (ready_) vkDestroySemaphore(d, std::exchange(ready_, VK_NULL_HANDLE), nullptr);
}

void SharedDeviceBuffer::submit_write(VkCommandBuffer cmd) {
  // The kernels' writes visible to whatever reads the buffer next (an engine's shaders, a copy).
  VkMemoryBarrier done{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  done.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  done.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_UNIFORM_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &done, 0, nullptr, 0,
                       nullptr);
  if (ready_) {
    context_.submit_and_wait(cmd, ready_, ready_value_ + 1);
    ++ready_value_;
  } else {
    context_.submit_and_wait(cmd);
  }
}

std::vector<float> SharedDeviceBuffer::read_back() const {
  std::vector<float> values(size_t(size_ / 4));
  if (values.empty()) return values;
  Buffer staging = context_.create_buffer(values.size() * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  VkCommandBuffer cmd = context_.begin();
  const VkBufferCopy region{0, 0, values.size() * 4};
  vkCmdCopyBuffer(cmd, buffer_, staging.handle(), 1, &region);
  VkMemoryBarrier host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &host, 0, nullptr, 0, nullptr);
  context_.submit_and_wait(cmd);
  std::memcpy(values.data(), staging.mapped(), values.size() * 4);
  return values;
}

}  // namespace exitance::vulkan
