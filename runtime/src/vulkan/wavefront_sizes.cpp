#include "wavefront_sizes.h"

#include <algorithm>

#include "wavefront_kernels.h"

namespace exitance::vulkan {

WavefrontSizes choose_wavefront_sizes(const Context& context, const VulkanDeviceOptions& options) {
  const bool cpu_device = context.info().type == VulkanDeviceType::Cpu;
  // Paths in flight: on a GPU, more paths hide more latency, and the larger batches they allow
  // (work items = paths x work_items_per_path) mean fewer drains per sample (H100, 1 M live texels:
  // 1 Mi paths 1.46 s, 4 Mi paths 1.20 s, bench/results/vulkan-gpu.md; H200, 256 spp: 4 / 8 / 16 Mi
  // paths 0.847 / 0.798 / 0.774 s on the building, 0.669 / 0.633 / 0.620 s on the open city, same
  // bits, bench/results/open-city-gpu.md). 4 Mi paths take about 1.7 GB (path state + results): the
  // most paths, up to 16 Mi, whose memory stays within an eighth of the device's (4 Mi from 16 GiB,
  // 8 Mi from 32 GiB, 16 Mi from 64 GiB); 1 Mi below 16 GiB.
  VkDeviceSize device_local = 0;
  const VkPhysicalDeviceMemoryProperties& memory = context.memory_properties();
  for (uint32_t h = 0; h < memory.memoryHeapCount; ++h)
    if (memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      device_local = std::max(device_local, memory.memoryHeaps[h].size);
  // An engine's adopted device renders the game too: at most 4 Mi paths there (VulkanDeviceOptions::max_paths sets more).
  const uint32_t most_paths = context.adopted() ? (1u << 22) : (1u << 24);
  uint32_t gpu_paths = 1u << 20;
  for (uint32_t paths = 1u << 22; paths <= most_paths && device_local >= (VkDeviceSize(paths >> 22) << 34); paths *= 2)
    gpu_paths = paths;
  WavefrontSizes sizes;
  sizes.paths = std::max<uint32_t>(options.max_paths ? options.max_paths : (cpu_device ? (1u << 14) : gpu_paths), kGroupSize);
  sizes.iterations_per_submit = options.iterations_per_submit ? options.iterations_per_submit : (cpu_device ? 8u : 32u);
  sizes.work_items_per_path = options.work_items_per_path ? options.work_items_per_path : 4u;
  // Node layout: quantized 64-byte nodes pay on CPU devices (lavapipe: fewer gathered words per
  // node), float 112-byte nodes on GPUs (the H100 traversal is bound by instructions, not by node
  // bytes: the BVH stays in L2).
  sizes.quantized_nodes = options.node_layout == VulkanNodeLayout::Automatic ? cpu_device
                                                                           : options.node_layout == VulkanNodeLayout::Quantized;
  sizes.round_stack_bound = cpu_device;
  return sizes;
}

uint32_t kernel_stack_bound(const WavefrontSizes& sizes, uint32_t bvh_stack_bound) {
  if (!sizes.round_stack_bound) return bvh_stack_bound;
  uint32_t bound = 32;
  while (bound < bvh_stack_bound) bound *= 2;
  return bound;
}

}  // namespace exitance::vulkan
