// The lighting stage traces only the texels that light can reach (sealed_texels.h); this puts its
// estimate back on the full texel list, so every later stage (exitance, pages, manifest) indexes
// texels as the G-buffer does.
#pragma once
#include <cstdint>
#include <vector>

#include "exitance/runtime/core/estimates.h"

namespace exitance {

// `traced` holds one texel per zero entry of `skipped`, in order; the result has one per entry of
// `skipped`, the skipped texels with no samples (samples = 0, all sums 0: mean_total() is 0, never
// NaN). Fields that are not per texel are kept unchanged. Taken by value: a moved-in estimate is
// not copied (under a time budget this runs on the lighting stage's clock).
LightmapEstimate expand_lightmap_estimate(LightmapEstimate traced, const std::vector<uint8_t>& skipped);

}  // namespace exitance
