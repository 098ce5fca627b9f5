// The wavefront's compute pipelines (shaders/wavefront/*.comp, embedded SPIR-V) over one descriptor
// set whose bindings are gpu_layout.h's, and the timestamp queries of their launches.
#pragma once
#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>

#include "exitance/common/gpu_layout.h"
#include "vulkan_context.h"

namespace exitance::vulkan {

// A pipeline per kernel; the probe variants of generate and shade are the same SPIR-V specialised
// for probe work items (bindings.glsl kProbeMode).
enum class Kernel {
  Generate, GenerateProbes, Prepare, Shade, ShadeProbes, Connect, Extend, ReduceTexels, ReduceProbes, TraversalOnly,
  LightSubpaths, Count
};

const char* kernel_file(Kernel kernel);  // "shade.comp (probes)", ...

// Threads per workgroup of every kernel but prepare (local_size_x in shaders/wavefront/*.comp).
constexpr uint32_t kGroupSize = 64;
constexpr uint32_t groups_for(uint64_t threads) { return uint32_t((threads + kGroupSize - 1) / kGroupSize); }

// Push constants of every kernel: which ray queue is read (ping-pong), and prepare's mode.
struct PushConstants {
  uint32_t ray_queue = 0;
  uint32_t mode = 0;
};

// The buffers of one descriptor set, each at its gpu_layout.h binding; write() checks all are set.
class DescriptorWrites {
 public:
  void set(uint32_t binding, const Buffer& buffer) { buffers_[binding] = buffer.handle(); }
  void write(VkDevice device, VkDescriptorSet set) const;

 private:
  std::array<VkBuffer, kBindingCount> buffers_{};
};

class WavefrontKernels {
 public:
  // `stack_bound`: traversal stack entries; `quantized_nodes`: the BVH node layout (bvh.glsl).
  WavefrontKernels(Context& context, uint32_t stack_bound, bool quantized_nodes);
  ~WavefrontKernels();
  WavefrontKernels(const WavefrontKernels&) = delete;
  WavefrontKernels& operator=(const WavefrontKernels&) = delete;

  void write_descriptors(const DescriptorWrites& writes) { writes.write(context_.device(), set_); }
  VkPipeline pipeline(Kernel k) const { return pipelines_[size_t(k)]; }
  VkPipelineLayout layout() const { return layout_; }
  VkDescriptorSet descriptor_set() const { return set_; }
  VkQueryPool timestamp_queries() const { return queries_; }  // null where the queue has no timestamps
  static constexpr uint32_t kMaxTimestamps = 1024;

 private:
  void release();
  Context& context_;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  std::array<VkPipeline, size_t(Kernel::Count)> pipelines_{};
  VkQueryPool queries_ = VK_NULL_HANDLE;
};

}  // namespace exitance::vulkan
