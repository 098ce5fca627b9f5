// Integrator::bake on the wavefront: the live texels are the work items; the PassScheduler's passes
// of samples are cut into batches of at most work_items_per_batch (texel, sample) items; with a
// target error, converged texels leave the work list between passes.
#pragma once
#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/integrator_settings.h"
#include "exitance/runtime/texel_gbuffer.h"
#include "wavefront_batch.h"

namespace exitance::vulkan {

class LightmapDriver {
 public:
  explicit LightmapDriver(WavefrontBatchRunner& runner) : runner_(runner) {}
  LightmapEstimate bake(const TexelGBuffer& gbuffer, const IntegratorSettings& settings);

 private:
  void upload_texels(const TexelGBuffer& gbuffer, const std::vector<uint32_t>& work_list);
  // The texels of `work_list` whose relative standard error is still above the target.
  std::vector<uint32_t> unconverged(const std::vector<uint32_t>& work_list, size_t texel_count, double target);

  WavefrontBatchRunner& runner_;
};

}  // namespace exitance::vulkan
