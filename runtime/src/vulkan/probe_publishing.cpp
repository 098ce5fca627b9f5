#include "probe_publishing.h"

#include <cstring>
#include <stdexcept>
#include <utility>

#include "exitance_spirv/publish_probes.h"

namespace exitance::vulkan {
namespace {

struct PublishProbesPush {
  uint32_t probe_count, switch_samples;
  float band_weight[3];
};

}  // namespace

ProbePublisher::ProbePublisher(Context& context, size_t grid_probes, const std::vector<uint32_t>& grid_index)
    : context_(context),
      probes_(grid_index.size()),
      grid_index_(grid_index),
      kernel_(context, std::vector<VkDescriptorType>(5, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER), uint32_t(sizeof(PublishProbesPush)),
              spirv_publish_probes, sizeof(spirv_publish_probes), 1, "publish_probes.comp") {
  VkDevice d = context.device();
  try {
    kept_ = context.create_storage_buffer(std::max<size_t>(probes_ * kKeptWords * 8, 16));
    index_ = context.create_storage_buffer(std::max<size_t>(probes_ * 4, 16));
    if (probes_ > 0) context.upload(index_, grid_index_.data(), probes_ * 4);
    out_.probes = uint32_t(grid_probes);
    out_.size = VkDeviceSize(std::max<size_t>(grid_probes, 1)) * 27 * 4;
    out_.queue_family = context.queue_family();
    // Shared by every queue family of the device, so an engine reading it on another family needs
    // no ownership transfer (only the semaphore wait).
    uint32_t family_count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(context.physical_device(), &family_count, nullptr);
    std::vector<uint32_t> families(family_count);
    for (uint32_t f = 0; f < family_count; ++f) families[f] = f;
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = out_.size;
    info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    info.sharingMode = family_count > 1 ? VK_SHARING_MODE_CONCURRENT : VK_SHARING_MODE_EXCLUSIVE;
    if (family_count > 1) info.queueFamilyIndexCount = family_count, info.pQueueFamilyIndices = families.data();
    check(vkCreateBuffer(d, &info, nullptr, &out_.buffer), "vkCreateBuffer (probes)");
    VkMemoryRequirements requirements;
    vkGetBufferMemoryRequirements(d, out_.buffer, &requirements);
    memory_ = context.allocate_device_local(requirements, "allocating the probe buffer");
    check(vkBindBufferMemory(d, out_.buffer, memory_, 0), "vkBindBufferMemory (probes)");
    if (context.timeline_semaphores()) {
      VkSemaphoreTypeCreateInfo type{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
      type.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
      VkSemaphoreCreateInfo semaphore{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
      semaphore.pNext = &type;
      check(vkCreateSemaphore(d, &semaphore, nullptr, &out_.ready), "vkCreateSemaphore (probes ready)");
    }
    // Probes not in use read 0.
    VkCommandBuffer cmd = context.begin();
    vkCmdFillBuffer(cmd, out_.buffer, 0, VK_WHOLE_SIZE, 0);
    context.submit_and_wait(cmd);
  } catch (...) {
    release();
    throw;
  }
}

ProbePublisher::~ProbePublisher() { release(); }

void ProbePublisher::release() {
  if (context_.hung()) return;  // a running submission may still use them (Context::cleanup)
  VkDevice d = context_.device();
  if (out_.buffer) vkDestroyBuffer(d, std::exchange(out_.buffer, VK_NULL_HANDLE), nullptr);
  if (memory_) vkFreeMemory(d, std::exchange(memory_, VK_NULL_HANDLE), nullptr);
  if (out_.ready) vkDestroySemaphore(d, std::exchange(out_.ready, VK_NULL_HANDLE), nullptr);
}

bool ProbePublisher::fits(size_t grid_probes, const std::vector<uint32_t>& grid_index) const {
  return out_.probes == grid_probes && grid_index == grid_index_;
}

void ProbePublisher::set_kept(const std::vector<double>& kept) {
  if (kept.size() != probes_ * kKeptWords) throw std::logic_error("ProbePublisher::set_kept: not kKeptWords per probe");
  if (!kept.empty()) context_.upload(kept_, kept.data(), kept.size() * 8);
}

const DeviceProbeBuffer& ProbePublisher::write(const ProbeAccumulators& sums, uint32_t switch_samples,
                                               const std::array<float, 3>& band_weight) {
  const std::array<VkDescriptorBufferInfo, 5> infos{{{sums.sh_sums.handle(), 0, VK_WHOLE_SIZE},
                                                     {sums.counts.handle(), 0, VK_WHOLE_SIZE},
                                                     {kept_.handle(), 0, VK_WHOLE_SIZE},
                                                     {index_.handle(), 0, VK_WHOLE_SIZE},
                                                     {out_.buffer, 0, VK_WHOLE_SIZE}}};
  kernel_.write_buffers(0, infos.data(), 5);
  VkCommandBuffer cmd = context_.begin();
  // After everything submitted to the queue before (an engine's reads of the buffer, the probe
  // batches writing the sums, uploads).
  VkMemoryBarrier before{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  before.srcAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT;
  before.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &before, 0, nullptr, 0,
                       nullptr);
  if (probes_ > 0) {
    kernel_.bind(cmd, 0);
    const PublishProbesPush push{uint32_t(probes_), switch_samples, {band_weight[0], band_weight[1], band_weight[2]}};
    kernel_.push(cmd, &push, sizeof(push));
    vkCmdDispatch(cmd, uint32_t((probes_ + 63) / 64), 1, 1);
  }
  VkMemoryBarrier done{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  done.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  done.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_UNIFORM_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &done, 0, nullptr, 0,
                       nullptr);
  if (out_.ready) context_.submit_and_wait(cmd, out_.ready, out_.ready_value + 1);
  else context_.submit_and_wait(cmd);
  if (out_.ready) ++out_.ready_value;
  return out_;
}

std::vector<float> ProbePublisher::read_back() {
  std::vector<float> values(size_t(out_.probes) * 27);
  if (values.empty()) return values;
  Buffer staging = context_.create_buffer(values.size() * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  VkCommandBuffer cmd = context_.begin();
  const VkBufferCopy region{0, 0, values.size() * 4};
  vkCmdCopyBuffer(cmd, out_.buffer, staging.handle(), 1, &region);
  VkMemoryBarrier host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &host, 0, nullptr, 0, nullptr);
  context_.submit_and_wait(cmd);
  std::memcpy(values.data(), staging.mapped(), values.size() * 4);
  return values;
}

}  // namespace exitance::vulkan
