// Grid guiding's fold on the device (shaders/wavefront/fold_guide.comp, issue 35 item 1): between
// learning passes, one dispatch folds the guide buffer's back sums into its learned section and
// rebuilds the front and CDF sections (common/guide_fold.h, GridGuidingCache::swap's code), so a
// guided bake makes no host round trip while it learns.
#pragma once
#include <cstdint>

#include "compute_kernel.h"
#include "vulkan_context.h"

namespace exitance::vulkan {

class GuideFoldKernel {
 public:
  explicit GuideFoldKernel(Context& context);
  // Folds every one of `records` records of the guide words in `guide` (gpu_layout.h kBindingGuide's
  // layout, with its learned section), `mix` the guided share of a learned record; one submission,
  // waited: the next pass reads the new table.
  void fold(const Buffer& guide, uint32_t records, float mix);

 private:
  Context& context_;
  ComputeKernel kernel_;
};

}  // namespace exitance::vulkan
