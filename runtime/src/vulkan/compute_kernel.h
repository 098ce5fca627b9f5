// One compute pipeline over a fixed list of descriptors, with its set layout, push constants and a
// few descriptor sets of its own: what the runtime's small kernels outside the wavefront
// (publish.comp, page_images.comp) each need, made and released in one place.
#pragma once
#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "vulkan_context.h"

namespace exitance::vulkan {

class ComputeKernel {
 public:
  // `bindings`: the descriptor type of bindings 0, 1, ...; `sets`: descriptor sets allocated;
  // `name` names the kernel in errors ("publish.comp").
  ComputeKernel(Context& context, const std::vector<VkDescriptorType>& bindings, uint32_t push_bytes,
                const uint32_t* spirv, size_t spirv_bytes, uint32_t sets, const char* name);
  ~ComputeKernel();
  ComputeKernel(const ComputeKernel&) = delete;
  ComputeKernel& operator=(const ComputeKernel&) = delete;

  VkDescriptorSet set(uint32_t index = 0) const { return sets_.at(index); }
  // Binds the pipeline and set `index` on `cmd`.
  void bind(VkCommandBuffer cmd, uint32_t index = 0) const;
  void push(VkCommandBuffer cmd, const void* data, uint32_t bytes) const;
  // Points bindings 0 .. count - 1 of set `index` (storage buffers) at `buffers`.
  void write_buffers(uint32_t index, const VkDescriptorBufferInfo* buffers, uint32_t count) const;

 private:
  void release();
  Context& context_;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  std::vector<VkDescriptorSet> sets_;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
};

// Records the zeroing of `counters` (a kernel's host-visible counts of what it did) and a barrier
// that makes it, and every transfer or compute write recorded before, visible to the compute
// shaders recorded next (publish.comp, denoise_indirect.comp).
void clear_counters_before_compute(VkCommandBuffer cmd, const Buffer& counters);

// Records a barrier that makes every transfer, compute or host write before it visible to the
// compute shaders recorded next (the small kernels that rewrite sums in place: scale_light_layers,
// scale_probe_layers).
void writes_visible_to_compute(VkCommandBuffer cmd);
// Records a barrier after compute shaders: their reads and writes done before later transfers,
// compute shaders and host reads (a download, the next pass, the host's mapped read).
void compute_done_before_all(VkCommandBuffer cmd);

}  // namespace exitance::vulkan
