#include "voxel_exitance_publishing.h"

#include <algorithm>
#include <array>
#include <bit>
#include <stdexcept>

#include "exitance_spirv/publish_voxel_exitance.h"

namespace exitance::vulkan {
namespace {

struct VoxelPush {
  uint32_t pass_index, first, count;
};
constexpr uint32_t kGroup = 64;

}  // namespace

VoxelExitancePublisher::VoxelExitancePublisher(Context& context, const formats::SparseVoxelOctree& svo)
    : context_(context),
      level_begin_(svo.level_begin),
      out_buffer_(context, VkDeviceSize(std::max<size_t>(svo.nodes.size(), 1)) * 24, "voxel exitance"),
      kernel_(context, std::vector<VkDescriptorType>(8, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER), uint32_t(sizeof(VoxelPush)),
              spirv_publish_voxel_exitance, sizeof(spirv_publish_voxel_exitance), 1, "publish_voxel_exitance.comp") {
  const size_t nodes = svo.nodes.size();
  if (nodes == 0 || level_begin_.size() != size_t(svo.depth) + 2) throw std::invalid_argument("VoxelExitancePublisher: an octree without its levels");
  std::vector<uint32_t> words(nodes * 4);
  for (size_t i = 0; i < nodes; ++i) {
    const formats::SvoNode& n = svo.nodes[i];
    words[i * 4] = i == 0 ? 0u : n.parent;
    words[i * 4 + 1] = n.first_child;
    words[i * 4 + 2] = uint32_t(std::popcount(unsigned(n.child_mask)));
  }
  nodes_ = context.create_storage_buffer(words.size() * 4);
  context.upload(nodes_, words.data(), words.size() * 4);
  scratch_ = context.create_storage_buffer(nodes * 2 * 4 * 8);
  state_ = context.create_storage_buffer(nodes * 2 * 4);
  side_first_ = context.create_storage_buffer((2 * nodes + 1) * 4);
  entries_ = context.create_storage_buffer(16);
  out_ = {out_buffer_.buffer(), VkDeviceSize(nodes) * 24, uint32_t(nodes), out_buffer_.ready(), 0, context.queue_family()};
}

void VoxelExitancePublisher::set_deposits(const VoxelDeposits& deposits) {
  const size_t nodes = out_.nodes;
  if (deposits.side_first.size() != 2 * nodes + 1 || deposits.flipped.size() != nodes)
    throw std::logic_error("VoxelExitancePublisher::set_deposits: deposits of another octree");
  context_.upload(side_first_, deposits.side_first.data(), deposits.side_first.size() * 4);
  const size_t entries = deposits.texel.size();
  std::vector<float> words(std::max<size_t>(entries, 1) * 9, 0.0f);
  for (size_t e = 0; e < entries; ++e) {
    float* w = &words[e * 9];
    w[0] = std::bit_cast<float>(deposits.texel[e]);
    w[1] = deposits.weight[e];
    w[2] = deposits.emitted[e].x, w[3] = deposits.emitted[e].y, w[4] = deposits.emitted[e].z;
    w[5] = deposits.albedo[e].x, w[6] = deposits.albedo[e].y, w[7] = deposits.albedo[e].z;
  }
  if (entries_.size() < words.size() * 4) entries_ = context_.create_storage_buffer(words.size() * 4);
  context_.upload(entries_, words.data(), words.size() * 4);
  // The flip bits into the node words (the rest was uploaded at construction).
  std::vector<uint32_t> node_words(nodes * 4);
  context_.download(nodes_, node_words.data(), node_words.size() * 4);
  for (size_t i = 0; i < nodes; ++i) node_words[i * 4 + 3] = deposits.flipped[i];
  context_.upload(nodes_, node_words.data(), node_words.size() * 4);
  deposits_set_ = true;
}

const DeviceVoxelExitance& VoxelExitancePublisher::write(const DeviceLightmap& lightmap) {
  if (!deposits_set_) throw std::logic_error("VoxelExitancePublisher::write before set_deposits");
  const std::array<VkDescriptorBufferInfo, 8> infos{{{lightmap.sums.sums.handle(), 0, VK_WHOLE_SIZE},
                                                     {lightmap.sums.samples.handle(), 0, VK_WHOLE_SIZE},
                                                     {side_first_.handle(), 0, VK_WHOLE_SIZE},
                                                     {entries_.handle(), 0, VK_WHOLE_SIZE},
                                                     {nodes_.handle(), 0, VK_WHOLE_SIZE},
                                                     {scratch_.handle(), 0, VK_WHOLE_SIZE},
                                                     {out_.buffer, 0, VK_WHOLE_SIZE},
                                                     {state_.handle(), 0, VK_WHOLE_SIZE}}};
  kernel_.write_buffers(0, infos.data(), 8);
  VkCommandBuffer cmd = context_.begin();
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  // After everything submitted before (an engine's reads of the buffer, the publish, uploads).
  barrier.srcAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT;
  barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1,
                       &barrier, 0, nullptr, 0, nullptr);
  vkCmdFillBuffer(cmd, scratch_.handle(), 0, VK_WHOLE_SIZE, 0);  // internal nodes sum from 0
  barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  const auto between = [&] {
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0,
                         1, &barrier, 0, nullptr, 0, nullptr);
  };
  kernel_.bind(cmd, 0);
  const auto dispatch = [&](uint32_t pass, uint32_t first, uint32_t count) {
    if (count == 0) return;
    between();
    const VoxelPush push{pass, first, count};
    kernel_.push(cmd, &push, sizeof(push));
    vkCmdDispatch(cmd, (count + kGroup - 1) / kGroup, 1, 1);
  };
  const uint32_t depth = uint32_t(level_begin_.size() - 2);
  const auto level = [&](uint32_t l) { return std::pair<uint32_t, uint32_t>{level_begin_[l], level_begin_[l + 1] - level_begin_[l]}; };
  dispatch(0, level(depth).first, level(depth).second);
  for (uint32_t l = depth; l-- > 0;) dispatch(1, level(l).first, level(l).second);
  dispatch(2, 0, out_.nodes);
  for (uint32_t l = 1; l <= depth; ++l) dispatch(3, level(l).first, level(l).second);
  out_buffer_.submit_write(cmd);
  out_.ready_value = out_buffer_.ready_value();
  return out_;
}

}  // namespace exitance::vulkan
