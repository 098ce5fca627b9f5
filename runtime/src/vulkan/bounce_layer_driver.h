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

#include "exitance/runtime/core/emitter_guiding_cache.h"
#include "exitance/runtime/core/per_bounce_bake.h"
#include "exitance/runtime/scene.h"
#include "compute_kernel.h"
#include "emitter_guide_buffer.h"
#include "wavefront_batch.h"

namespace exitance::vulkan {

class BounceLayerDriver final : public BounceLayerEstimator {
 public:
  // `source`: the scene's triangles' instances and lightmap UVs (may be null: every gather hit is
  // then estimated on the fly).
  // `lighting`: the scene the device holds, for emitter guiding's cache (settings.emitter_guiding;
  // may be null otherwise).
  BounceLayerDriver(WavefrontBatchRunner& runner, std::shared_ptr<const Scene> source, const TexelGBuffer& gbuffer,
                    const IntegratorSettings& settings, std::shared_ptr<const LightingScene> lighting = nullptr);
  ~BounceLayerDriver() override;
  // What emitter guiding's cache held at the end (nothing when it was off), and settings'
  // inspect_emitter_guiding called with it.
  void report(LightmapEstimate::EmitterGuidingReport& out) const;

  void estimate(const BounceLayerPass& pass, const std::vector<BounceLayerCache>& caches,
                const std::vector<uint64_t>& cache_versions) override;
  BounceGatherCounts counts() const override;
  // The layer caches are built on the device (bounce_cache.comp) from the means the host loop
  // passes, unless settings.bounce_caches_on_host asks for the host's BounceLayerCache pages.
  bool builds_caches() const override { return !settings_.bounce_caches_on_host; }
  void build_cache(size_t layer, const std::vector<Vec3>& means, const std::vector<uint8_t>& valid) override;

 private:
  void prepare();
  void upload_caches(size_t layers, const std::vector<BounceLayerCache>& caches, const std::vector<uint64_t>& versions);
  // The cache buffer with room for `layers` layers, its header and tables on the device; when it
  // grows, what it held (the layers built so far) is copied into the larger one.
  void reserve_device_layers(size_t layers);
  void upload_emitter_section();

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
  // Host-visible, kept (Context::keep_staging): each pass's sums come back and each cache's means go
  // up through it (a new pinned buffer per transfer cost its allocation and page faults: 48 MB at
  // 1 M texels).
  Buffer staging_;
  // Emitter guiding (emitter_guide_buffer.h) on the direct-light samples (B_0's, and B_1's traced
  // ones at gather hits), one cache through all layers' passes, folded before each pass as the CPU's
  // estimator does (cpu/cpu_bounce_integrator.cpp).
  std::unique_ptr<EmitterGuidingCache> emitter_guide_;
  std::unique_ptr<EmitterGuideBuffer> emitter_buffer_;
  std::unique_ptr<GuideFoldKernel> emitter_fold_;  // made by the first device fold
  uint32_t learned_samples_ = 0;
  // Device-built caches (bounce_cache.comp): the kernel, per live texel its page texel, position and
  // normal (uploaded once), the means of the layer being built, a fill flag per page texel, the pages.
  std::unique_ptr<ComputeKernel> cache_kernel_;
  Buffer cache_texels_, cache_means_, cache_flags_, cache_pages_;
  size_t page_texels_ = 0;
};

}  // namespace exitance::vulkan
