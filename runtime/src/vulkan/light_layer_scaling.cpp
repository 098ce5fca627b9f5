#include "light_layer_scaling.h"

#include <array>
#include <cstring>
#include <stdexcept>

#include "exitance_spirv/scale_light_layers.h"

namespace exitance::vulkan {
namespace {

struct ScalePush {
  uint32_t texel_count, recorded, scaled, directional, proportional;
};

}  // namespace

LightLayerScaler::LightLayerScaler(Context& context)
    : context_(context),
      kernel_(context, std::vector<VkDescriptorType>(5, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER), sizeof(ScalePush), spirv_scale_light_layers,
              sizeof(spirv_scale_light_layers), kSets, "scale_light_layers.comp") {
  // One dispatch over no texels, so drivers that compile a pipeline at its first dispatch (lavapipe)
  // do it here and not inside the first edit.
  factors_ = context_.create_buffer(sizeof(Vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
  std::array<VkDescriptorBufferInfo, 5> infos{};
  infos.fill({factors_.handle(), 0, VK_WHOLE_SIZE});
  kernel_.write_buffers(0, infos.data(), 5);
  VkCommandBuffer cmd = context_.begin();
  kernel_.bind(cmd, 0);
  const ScalePush push{0, 1, 0, 0, 0};
  kernel_.push(cmd, &push, sizeof(push));
  vkCmdDispatch(cmd, 1, 1, 1);
  context_.submit_and_wait(cmd);
}

void LightLayerScaler::scale(const std::vector<Vec4>& factors, const ScaledEstimate& accumulation, const std::vector<ScaledEstimate>& others) {
  if (others.size() + 1 > kSets) throw std::logic_error("LightLayerScaler::scale: more estimates than descriptor sets");
  std::vector<ScaledEstimate> estimates = others;
  estimates.push_back(accumulation);  // last: the others read its sums from before
  for (const ScaledEstimate& e : estimates)
    if (!e.sums || size_t(e.light_layers) != factors.size() || e.texels != accumulation.texels || e.recorded != accumulation.recorded ||
        e.directional != accumulation.directional)
      throw std::logic_error("LightLayerScaler::scale: an estimate not shaped as the accumulation");
  // The scaled layers only, each as rgb and its layer index (the kernel's cost is per scaled layer).
  std::vector<Vec4> scaled;
  for (size_t l = 0; l < factors.size(); ++l)
    if (factors[l].w != 0) scaled.push_back(Vec4(factors[l].x, factors[l].y, factors[l].z, float(l)));
  if (scaled.empty() || accumulation.texels == 0) return;
  const size_t bytes = scaled.size() * sizeof(Vec4);
  if (!factors_.handle() || factors_.size() < bytes) factors_ = context_.create_buffer(bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
  std::memcpy(factors_.mapped(), scaled.data(), bytes);  // host-coherent: visible to the submission below
  for (uint32_t i = 0; i < estimates.size(); ++i) {
    const std::array<VkDescriptorBufferInfo, 5> infos{{{estimates[i].sums->sums.handle(), 0, VK_WHOLE_SIZE},
                                                       {estimates[i].sums->bounce_sums.handle(), 0, VK_WHOLE_SIZE},
                                                       {factors_.handle(), 0, VK_WHOLE_SIZE},
                                                       {accumulation.sums->sums.handle(), 0, VK_WHOLE_SIZE},
                                                       {accumulation.sums->bounce_sums.handle(), 0, VK_WHOLE_SIZE}}};
    kernel_.write_buffers(i, infos.data(), 5);
  }
  VkCommandBuffer cmd = context_.begin();
  writes_visible_to_compute(cmd);
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  for (uint32_t i = 0; i < estimates.size(); ++i) {
    const ScaledEstimate& e = estimates[i];
    const bool last = i + 1 == estimates.size();
    if (last && i > 0) {  // the others' reads of the accumulation before it changes
      barrier.srcAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
      barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
      vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &barrier, 0, nullptr, 0,
                           nullptr);
    }
    kernel_.bind(cmd, i);
    const ScalePush push{uint32_t(e.texels), uint32_t(e.recorded), uint32_t(scaled.size()), e.directional ? 1u : 0u,
                         !last && e.proportional ? 1u : 0u};
    kernel_.push(cmd, &push, sizeof(push));
    vkCmdDispatch(cmd, uint32_t((e.texels + 63) / 64), 1, 1);
  }
  compute_done_before_all(cmd);
  context_.submit_and_wait(cmd);
}

}  // namespace exitance::vulkan
