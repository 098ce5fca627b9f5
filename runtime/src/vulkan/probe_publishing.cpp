#include "probe_publishing.h"

#include <algorithm>
#include <stdexcept>

#include "exitance_spirv/publish_probes.h"

namespace exitance::vulkan {
namespace {

struct PublishProbesPush {
  uint32_t probe_count, switch_samples;
  float band_weight[3];
  uint32_t change;
};

}  // namespace

ProbePublisher::ProbePublisher(Context& context, size_t grid_probes, const std::vector<uint32_t>& grid_index)
    : context_(context),
      probes_(grid_index.size()),
      grid_index_(grid_index),
      out_buffer_(context, VkDeviceSize(std::max<size_t>(grid_probes, 1)) * 27 * 4, "probes"),
      kernel_(context, std::vector<VkDescriptorType>(5, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER), uint32_t(sizeof(PublishProbesPush)),
              spirv_publish_probes, sizeof(spirv_publish_probes), 1, "publish_probes.comp") {
  kept_ = context.create_storage_buffer(std::max<size_t>(probes_ * kKeptWords * 8, 16));
  index_ = context.create_storage_buffer(std::max<size_t>(probes_ * 4, 16));
  if (probes_ > 0) context.upload(index_, grid_index_.data(), probes_ * 4);
  out_ = {out_buffer_.buffer(), out_buffer_.size(), uint32_t(grid_probes), out_buffer_.ready(), 0, context.queue_family()};
  // Probes not in use read 0.
  VkCommandBuffer cmd = context.begin();
  vkCmdFillBuffer(cmd, out_.buffer, 0, VK_WHOLE_SIZE, 0);
  context.submit_and_wait(cmd);
}

bool ProbePublisher::fits(size_t grid_probes, const std::vector<uint32_t>& grid_index) const {
  return out_.probes == grid_probes && grid_index == grid_index_;
}

void ProbePublisher::set_kept(const std::vector<double>& kept) {
  if (kept.size() != probes_ * kKeptWords) throw std::logic_error("ProbePublisher::set_kept: not kKeptWords per probe");
  if (!kept.empty()) context_.upload(kept_, kept.data(), kept.size() * 8);
}

const DeviceProbeBuffer& ProbePublisher::write(const ProbeAccumulators& sums, uint32_t switch_samples,
                                               const std::array<float, 3>& band_weight, bool change) {
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
    const PublishProbesPush push{uint32_t(probes_), switch_samples, {band_weight[0], band_weight[1], band_weight[2]},
                                 change ? 1u : 0u};
    kernel_.push(cmd, &push, sizeof(push));
    vkCmdDispatch(cmd, uint32_t((probes_ + 63) / 64), 1, 1);
  }
  out_buffer_.submit_write(cmd);
  out_.ready_value = out_buffer_.ready_value();
  return out_;
}

}  // namespace exitance::vulkan
