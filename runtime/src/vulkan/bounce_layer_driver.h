// The per-bounce mode (IntegratorMode::Bounces) on the wavefront: the core's host loop
// (core/per_bounce_bake.h) calls this estimator for each layer pass. A pass uploads the layer
// caches that changed since the last one (gpu_layout.h kBindingBounceCache: the probe SH sums'
// buffer, which lightmap bakes leave unused), then runs the texels through the wavefront's batches
// with GpuParams::bounce_flags set (shaders/include/bounce_pass.glsl) and adds the downloaded
// per-texel sums to the layer's. The texel buffers are this bake's while it runs, as in
// LightmapDriver::bake.
#pragma once
#include <memory>
#include <vector>

#include "exitance/runtime/core/per_bounce_bake.h"
#include "exitance/runtime/scene.h"
#include "wavefront_batch.h"

namespace exitance::vulkan {

class BounceLayerDriver final : public BounceLayerEstimator {
 public:
  // `source`: the scene's triangles' instances and lightmap UVs (may be null: every gather hit is
  // then estimated on the fly).
  BounceLayerDriver(WavefrontBatchRunner& runner, std::shared_ptr<const Scene> source, const TexelGBuffer& gbuffer,
                    const IntegratorSettings& settings);

  void estimate(const BounceLayerPass& pass, const std::vector<BounceLayerCache>& caches,
                const std::vector<uint64_t>& cache_versions) override;
  BounceGatherCounts counts() const override;

 private:
  void prepare();
  void upload_caches(size_t layers, const std::vector<BounceLayerCache>& caches, const std::vector<uint64_t>& versions);

  WavefrontBatchRunner& runner_;
  std::shared_ptr<const Scene> source_;
  const TexelGBuffer& gbuffer_;
  const IntegratorSettings& settings_;
  bool prepared_ = false;
  bool tables_uploaded_ = false;  // header and tables on the device (the first upload writes everything)
  size_t max_work_ = 0;
  GpuParams params_{};
  BatchTotals totals_;
  uint64_t gathers_ = 0, texelless_ = 0, back_faces_ = 0;
  std::vector<float> cache_words_;              // header, tables, then the layers uploaded so far
  size_t layer_words_ = 0, first_layer_word_ = 0;
  std::vector<uint64_t> uploaded_versions_;     // per layer, the cache version on the device (0: none)
  std::vector<uint32_t> work_list_;
};

}  // namespace exitance::vulkan
