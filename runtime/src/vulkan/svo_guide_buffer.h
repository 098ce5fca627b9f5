// SVO guiding's data on the device (gpu_layout.h kGuideLocatorSvo, in the guide binding): the
// fields of core/svo_guiding_fields.h packed as its device contract says (octree links, bin per
// node, record per bin and class, fronts, CDFs), and the vertex counts the kernels add in counting
// passes, read back into the fields before each rebuild. The fields themselves (bins, capture
// origins, traced cone reads, CDFs) are built on the host by the same code as the CPU backend's.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "exitance/runtime/core/svo_guiding_fields.h"
#include "wavefront_batch.h"

namespace exitance::vulkan {

class SvoGuideBuffer {
 public:
  // Packs `fields` as they are now (links, bins, records, fronts, CDFs; counts at 0).
  explicit SvoGuideBuffer(const SvoGuidingFields& fields);

  // The whole buffer onto the device (growing and rebinding the binding).
  void upload(WavefrontBatchRunner& runner) const;
  // After a counting pass: the device's counts into `fields` (import_counts), zeroed on the device.
  void import_counts(WavefrontBatchRunner& runner, SvoGuidingFields& fields);
  // After a rebuild: bins, records, fronts and CDFs packed again and uploaded.
  void repack(WavefrontBatchRunner& runner, const SvoGuidingFields& fields);

  size_t bytes() const { return words_.size() * 4; }

 private:
  void pack(const SvoGuidingFields& fields);

  std::vector<uint32_t> words_;
  size_t counts_ = 0;  // first word of the back section (the counts)
};

}  // namespace exitance::vulkan
