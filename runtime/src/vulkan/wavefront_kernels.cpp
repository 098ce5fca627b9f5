#include "wavefront_kernels.h"

#include <stdexcept>
#include <string>
#include <utility>

#include "exitance_spirv/bench_rays.h"
#include "exitance_spirv/connect.h"
#include "exitance_spirv/extend.h"
#include "exitance_spirv/generate.h"
#include "exitance_spirv/light_subpaths.h"
#include "exitance_spirv/prepare.h"
#include "exitance_spirv/reduce.h"
#include "exitance_spirv/reduce_probes.h"
#include "exitance_spirv/shade.h"

namespace exitance::vulkan {
namespace {

struct KernelSource {
  const uint32_t* code;
  size_t bytes;
  bool probe_mode;
  const char* file;
};

KernelSource source_of(Kernel k) {
  switch (k) {
    case Kernel::Generate: return {spirv_generate, sizeof(spirv_generate), false, "generate.comp"};
    case Kernel::GenerateProbes: return {spirv_generate, sizeof(spirv_generate), true, "generate.comp (probes)"};
    case Kernel::Prepare: return {spirv_prepare, sizeof(spirv_prepare), false, "prepare.comp"};
    case Kernel::Shade: return {spirv_shade, sizeof(spirv_shade), false, "shade.comp"};
    case Kernel::ShadeProbes: return {spirv_shade, sizeof(spirv_shade), true, "shade.comp (probes)"};
    case Kernel::Connect: return {spirv_connect, sizeof(spirv_connect), false, "connect.comp"};
    case Kernel::Extend: return {spirv_extend, sizeof(spirv_extend), false, "extend.comp"};
    case Kernel::ReduceTexels: return {spirv_reduce, sizeof(spirv_reduce), false, "reduce.comp"};
    case Kernel::ReduceProbes: return {spirv_reduce_probes, sizeof(spirv_reduce_probes), false, "reduce_probes.comp"};
    case Kernel::TraversalOnly: return {spirv_bench_rays, sizeof(spirv_bench_rays), false, "bench_rays.comp"};
    case Kernel::LightSubpaths: return {spirv_light_subpaths, sizeof(spirv_light_subpaths), false, "light_subpaths.comp"};
    default: throw std::logic_error("no such kernel");
  }
}

}  // namespace

const char* kernel_file(Kernel kernel) { return source_of(kernel).file; }

void DescriptorWrites::write(VkDevice device, VkDescriptorSet set) const {
  std::array<VkDescriptorBufferInfo, kBindingCount> infos{};
  std::array<VkWriteDescriptorSet, kBindingCount> writes{};
  for (uint32_t i = 0; i < kBindingCount; ++i) {
    if (!buffers_[i]) throw std::logic_error("wavefront binding " + std::to_string(i) + " has no buffer");
    infos[i] = {buffers_[i], 0, VK_WHOLE_SIZE};
    writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[i].dstSet = set;
    writes[i].dstBinding = i;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
  }
  vkUpdateDescriptorSets(device, kBindingCount, writes.data(), 0, nullptr);
}

WavefrontKernels::WavefrontKernels(Context& context, uint32_t stack_bound, bool quantized_nodes) : context_(context) {
  VkDevice d = context.device();
  try {
    std::array<VkDescriptorSetLayoutBinding, kBindingCount> bindings{};
    for (uint32_t i = 0; i < kBindingCount; ++i)
      bindings[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    set_info.bindingCount = kBindingCount;
    set_info.pBindings = bindings.data();
    check(vkCreateDescriptorSetLayout(d, &set_info, nullptr, &set_layout_), "vkCreateDescriptorSetLayout");
    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(PushConstants)};
    VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layout_info.setLayoutCount = 1;
    layout_info.pSetLayouts = &set_layout_;
    layout_info.pushConstantRangeCount = 1;
    layout_info.pPushConstantRanges = &range;
    check(vkCreatePipelineLayout(d, &layout_info, nullptr, &layout_), "vkCreatePipelineLayout");
    VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kBindingCount};
    VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pool_info.maxSets = 1;
    pool_info.poolSizeCount = 1;
    pool_info.pPoolSizes = &pool_size;
    check(vkCreateDescriptorPool(d, &pool_info, nullptr, &pool_), "vkCreateDescriptorPool");
    VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    alloc.descriptorPool = pool_;
    alloc.descriptorSetCount = 1;
    alloc.pSetLayouts = &set_layout_;
    check(vkAllocateDescriptorSets(d, &alloc, &set_), "vkAllocateDescriptorSets");

    // Specialization: 0 = traversal stack bound, 1 = node layout (quantized or float; bvh.glsl),
    // 2 = probe work items (bindings.glsl kProbeMode).
    const VkSpecializationMapEntry entries[3] = {
        {0, 0, sizeof(uint32_t)}, {1, sizeof(uint32_t), sizeof(uint32_t)}, {2, 2 * sizeof(uint32_t), sizeof(VkBool32)}};
    for (size_t k = 0; k < pipelines_.size(); ++k) {
      const KernelSource source = source_of(Kernel(k));
      const uint32_t spec_values[3] = {stack_bound, quantized_nodes ? 1u : 0u, source.probe_mode ? 1u : 0u};
      const VkSpecializationInfo spec{3, entries, sizeof(spec_values), spec_values};
      VkShaderModuleCreateInfo module_info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
      module_info.codeSize = source.bytes;
      module_info.pCode = source.code;
      VkShaderModule module;
      check(vkCreateShaderModule(d, &module_info, nullptr, &module), "vkCreateShaderModule");
      VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
      info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
      info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
      info.stage.module = module;
      info.stage.pName = "main";
      info.stage.pSpecializationInfo = &spec;
      info.layout = layout_;
      const VkResult r = vkCreateComputePipelines(d, VK_NULL_HANDLE, 1, &info, nullptr, &pipelines_[k]);
      vkDestroyShaderModule(d, module, nullptr);
      check(r, (std::string("creating the pipeline of ") + source.file).c_str());
    }
    if (context.timestamps()) {
      VkQueryPoolCreateInfo q{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
      q.queryType = VK_QUERY_TYPE_TIMESTAMP;
      q.queryCount = kMaxTimestamps;
      check(vkCreateQueryPool(d, &q, nullptr, &queries_), "vkCreateQueryPool");
    }
  } catch (...) {
    release();
    throw;
  }
}

WavefrontKernels::~WavefrontKernels() { release(); }

void WavefrontKernels::release() {
  if (context_.hung()) return;  // a running submission may still use them (Context::cleanup)
  VkDevice d = context_.device();
  for (VkPipeline& p : pipelines_)
    if (p) vkDestroyPipeline(d, std::exchange(p, VK_NULL_HANDLE), nullptr);
  if (queries_) vkDestroyQueryPool(d, std::exchange(queries_, VK_NULL_HANDLE), nullptr);
  if (pool_) vkDestroyDescriptorPool(d, std::exchange(pool_, VK_NULL_HANDLE), nullptr);
  if (layout_) vkDestroyPipelineLayout(d, std::exchange(layout_, VK_NULL_HANDLE), nullptr);
  if (set_layout_) vkDestroyDescriptorSetLayout(d, std::exchange(set_layout_, VK_NULL_HANDLE), nullptr);
}

}  // namespace exitance::vulkan
