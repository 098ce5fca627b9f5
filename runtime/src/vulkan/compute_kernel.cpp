#include "compute_kernel.h"

#include <map>
#include <string>
#include <utility>

namespace exitance::vulkan {

ComputeKernel::ComputeKernel(Context& context, const std::vector<VkDescriptorType>& bindings, uint32_t push_bytes,
                             const uint32_t* spirv, size_t spirv_bytes, uint32_t sets, const char* name)
    : context_(context) {
  VkDevice d = context.device();
  const std::string what = std::string(" (") + name + ")";
  try {
    std::vector<VkDescriptorSetLayoutBinding> layout_bindings(bindings.size());
    std::map<VkDescriptorType, uint32_t> per_type;
    for (uint32_t i = 0; i < bindings.size(); ++i) {
      layout_bindings[i] = {i, bindings[i], 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
      per_type[bindings[i]] += sets;
    }
    VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    set_info.bindingCount = uint32_t(layout_bindings.size());
    set_info.pBindings = layout_bindings.data();
    check(vkCreateDescriptorSetLayout(d, &set_info, nullptr, &set_layout_), ("vkCreateDescriptorSetLayout" + what).c_str());
    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes};
    VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layout_info.setLayoutCount = 1;
    layout_info.pSetLayouts = &set_layout_;
    layout_info.pushConstantRangeCount = push_bytes ? 1 : 0;
    layout_info.pPushConstantRanges = &range;
    check(vkCreatePipelineLayout(d, &layout_info, nullptr, &layout_), ("vkCreatePipelineLayout" + what).c_str());
    std::vector<VkDescriptorPoolSize> pool_sizes;
    for (const auto& [type, count] : per_type) pool_sizes.push_back({type, count});
    VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pool_info.maxSets = sets;
    pool_info.poolSizeCount = uint32_t(pool_sizes.size());
    pool_info.pPoolSizes = pool_sizes.data();
    check(vkCreateDescriptorPool(d, &pool_info, nullptr, &pool_), ("vkCreateDescriptorPool" + what).c_str());
    sets_.assign(sets, VK_NULL_HANDLE);
    const std::vector<VkDescriptorSetLayout> layouts(sets, set_layout_);
    VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    alloc.descriptorPool = pool_;
    alloc.descriptorSetCount = sets;
    alloc.pSetLayouts = layouts.data();
    if (sets) check(vkAllocateDescriptorSets(d, &alloc, sets_.data()), ("vkAllocateDescriptorSets" + what).c_str());
    VkShaderModuleCreateInfo module_info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    module_info.codeSize = spirv_bytes;
    module_info.pCode = spirv;
    VkShaderModule module;
    check(vkCreateShaderModule(d, &module_info, nullptr, &module), ("vkCreateShaderModule" + what).c_str());
    VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module;
    info.stage.pName = "main";
    info.layout = layout_;
    const VkResult r = vkCreateComputePipelines(d, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline_);
    vkDestroyShaderModule(d, module, nullptr);
    check(r, ("creating the pipeline of " + std::string(name)).c_str());
  } catch (...) {
    release();
    throw;
  }
}

ComputeKernel::~ComputeKernel() { release(); }

void ComputeKernel::release() {
  if (context_.hung()) return;  // a running submission may still use them (Context::cleanup)
  VkDevice d = context_.device();
  if (pipeline_) vkDestroyPipeline(d, std::exchange(pipeline_, VK_NULL_HANDLE), nullptr);
  if (pool_) vkDestroyDescriptorPool(d, std::exchange(pool_, VK_NULL_HANDLE), nullptr);
  if (layout_) vkDestroyPipelineLayout(d, std::exchange(layout_, VK_NULL_HANDLE), nullptr);
  if (set_layout_) vkDestroyDescriptorSetLayout(d, std::exchange(set_layout_, VK_NULL_HANDLE), nullptr);
}

void ComputeKernel::bind(VkCommandBuffer cmd, uint32_t index) const {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &sets_.at(index), 0, nullptr);
}

void ComputeKernel::write_buffers(uint32_t index, const VkDescriptorBufferInfo* buffers, uint32_t count) const {
  std::vector<VkWriteDescriptorSet> writes(count);
  for (uint32_t b = 0; b < count; ++b) {
    writes[b] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[b].dstSet = set(index);
    writes[b].dstBinding = b;
    writes[b].descriptorCount = 1;
    writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[b].pBufferInfo = &buffers[b];
  }
  vkUpdateDescriptorSets(context_.device(), count, writes.data(), 0, nullptr);
}

void ComputeKernel::push(VkCommandBuffer cmd, const void* data, uint32_t bytes) const {
  vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, bytes, data);
}

void clear_counters_before_compute(VkCommandBuffer cmd, const Buffer& counters) {
  vkCmdFillBuffer(cmd, counters.handle(), 0, VK_WHOLE_SIZE, 0);
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

void writes_visible_to_compute(VkCommandBuffer cmd) {
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_HOST_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

void compute_done_before_all(VkCommandBuffer cmd) {
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT |
                          VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                       &barrier, 0, nullptr, 0, nullptr);
}

}  // namespace exitance::vulkan
