// Light subpaths on the wavefront (common/light_subpaths.h; gpu_layout.h kBindingLightSubpaths,
// shaders/wavefront/light_subpaths.comp): what a bake's batches need to trace a pool each before
// their paths start, for the texel and the probe drivers alike.
#pragma once
#include <cstddef>

#include "exitance/runtime/core/integrator_settings.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "wavefront_batch.h"

namespace exitance::vulkan {

class LightSubpathPools {
 public:
  // Where `lighting` starts subpaths: sets `params`' light-subpath fields (start probabilities, the
  // bounds' sphere, the deepest vertex, the shadow slots) and reserves the pool binding and the path
  // state for batches of up to `max_work` work items. Elsewhere inactive, `params` unchanged.
  LightSubpathPools(WavefrontBatchRunner& runner, const LightingScene& lighting, const IntegratorSettings& settings,
                    size_t max_work, GpuParams& params);
  bool active() const { return per_sample_ > 0; }
  // Before a batch of `work` work items: its pool's subpaths (IntegratorSettings::light_subpaths_per_sample
  // for each of the work items that connect: set_connected_share's share of them, at least the fewest).
  void before_batch(GpuParams& params, double work) const;
  // --guiding auto with light subpaths as its candidate (lightmap_driver.cpp): the share of the work
  // items whose paths connect (1 by default; 0: the fewest subpaths, which no path reads).
  void set_connected_share(double share) { connected_share_ = share; }
  // After it: a pool that did not fit was left empty; the binding grows past it for the next batches
  // (within the device's largest storage buffer).
  void after_batch(const BatchTotals& totals, GpuParams& params);

 private:
  uint64_t most_vertices() const;

  WavefrontBatchRunner& runner_;
  double per_sample_ = 0;
  double connected_share_ = 1;
};

}  // namespace exitance::vulkan
