// How big the wavefront is on a device: paths in flight, iterations per submission, work items per
// batch, and the BVH node layout. Measured choices: bench/results/vulkan-{lavapipe,gpu}.md.
#pragma once
#include <cstdint>

#include "exitance/runtime/vulkan/vulkan_integrator.h"
#include "vulkan_context.h"

namespace exitance::vulkan {

struct WavefrontSizes {
  uint32_t paths = 0;                  // path slots = threads of the largest launch
  uint32_t iterations_per_submit = 8;  // shade -> connect -> extend rounds per submission
  uint32_t work_items_per_path = 4;    // work items (item, sample) per batch = paths x this
  bool quantized_nodes = false;        // BVH node layout (bvh_quantization.h)
  bool round_stack_bound = false;      // CPU devices: the traversal stack in powers of two (below)
};

// The options' values, or where 0 / Automatic the device-dependent defaults.
WavefrontSizes choose_wavefront_sizes(const Context& context, const VulkanDeviceOptions& options);

// The kernels' traversal stack (specialization constant kStackSize) for a BVH that needs
// `bvh_stack_bound` entries. A GPU gets the exact bound (a larger private array costs it local
// memory). lavapipe compiles a pipeline per distinct constant with LLVM (20-60 s for all kernels on
// 2 cores, cached by Mesa per value), so there every scene shares one of a few values: 32, 64, ...
uint32_t kernel_stack_bound(const WavefrontSizes& sizes, uint32_t bvh_stack_bound);

}  // namespace exitance::vulkan
