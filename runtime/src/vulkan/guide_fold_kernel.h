// The guides' folds on the device (issue 35 item 1): between learning passes, one dispatch folds a
// guide's back sums into its learned section and rebuilds its front and CDF sections, so a guided
// bake makes no host round trip while it learns. Grid guiding: shaders/wavefront/fold_guide.comp
// (common/guide_fold.h, GridGuidingCache::swap's code); emitter guiding: fold_emitter_guide.comp
// (common/emitter_guide_fold.h, EmitterGuidingCache::swap's code).
#pragma once
#include <cstdint>

#include "compute_kernel.h"
#include "vulkan_context.h"

namespace exitance::vulkan {

enum class GuideFold { Grid, Emitter };

class GuideFoldKernel {
 public:
  GuideFoldKernel(Context& context, GuideFold which);
  // Grid: folds every one of `records` records of the guide words in `guide` (gpu_layout.h
  // kBindingGuide's layout, with its learned section), `mix` the guided share of a learned record.
  // One submission, waited: the next pass reads the new table.
  void fold_grid(const Buffer& guide, uint32_t records, float mix);
  // Emitter guiding: folds the `records` records of the emitter section at word `section` of
  // `guide` and returns how many of them sample what they learned (the section's
  // kEmitterGuideSampling word, zeroed first and read back: one more small wait).
  uint32_t fold_emitters(const Buffer& guide, uint32_t records, uint32_t section);

 private:
  // Records the dispatches over `records` records (push: first record, `argument`) into `cmd`.
  void record(VkCommandBuffer cmd, const Buffer& guide, uint32_t records, uint32_t argument);

  Context& context_;
  ComputeKernel kernel_;
};

}  // namespace exitance::vulkan
