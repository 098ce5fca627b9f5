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
};

// The options' values, or where 0 / Automatic the device-dependent defaults.
WavefrontSizes choose_wavefront_sizes(const Context& context, const VulkanDeviceOptions& options);

}  // namespace exitance::vulkan
