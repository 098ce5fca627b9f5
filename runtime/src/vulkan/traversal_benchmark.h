// Traversal alone (shaders/wavefront/bench_rays.comp): incoherent closest-hit rays, uniform
// origins in the scene bounds and uniform directions, timed with timestamps.
#pragma once
#include <cstdint>

#include "wavefront_batch.h"

namespace exitance::vulkan {

// Rays per second of GPU time, the best of `repetitions`; statistics under stage::kTraversalOnly.
double measure_incoherent_traversal(WavefrontBatchRunner& runner, uint32_t ray_count, int repetitions);

}  // namespace exitance::vulkan
