// Emitter guiding's data on the device (gpu_layout.h kEmitterGuide*, a section of the guide buffer
// after any other guide's): the EmitterGuidingCache's locator, patch tables and front tables packed
// as words, and its back tables' integer sums, learned by the kernels (shaders/include/
// emitter_guide.glsl) when a learning vertex's shadow ray arrives, read back and imported into the
// cache between passes. The fold, the clusters and the CDFs are the cache's own
// (EmitterGuidingCache::import_learned, end_pass), so both backends build their tables the same way.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "exitance/runtime/core/emitter_guiding_cache.h"
#include "wavefront_batch.h"

namespace exitance::vulkan {

// The cache a Vulkan bake's settings ask for (EmitterGuidingCache::for_bake on `lighting`, the
// scene the integrator holds), null when emitter guiding is off or there is nothing to guide;
// refused in one line when `lighting` no longer lists the device's emitters and punctual lights
// (its patch tables index the device's emitter list).
std::unique_ptr<EmitterGuidingCache> emitter_guide_for_device(const std::shared_ptr<const LightingScene>& lighting,
                                                              const GpuScene& device_scene, const TexelGBuffer& gbuffer,
                                                              const IntegratorSettings& settings);

class EmitterGuideBuffer {
 public:
  // Lays out and packs `cache` (its front tables as they are now) as a section starting at word
  // `base` of the guide buffer (after the other guides' words; kGuideHeaderWords at least).
  EmitterGuideBuffer(const EmitterGuidingCache& cache, size_t base);

  // Guide buffer words needed up to the end of this section.
  size_t end_word() const { return base_ + back_end_; }
  // GpuParams::emitter_guide while the cache is active: the section's first word.
  uint32_t params_offset() const { return uint32_t(base_); }

  // The section onto the device (the buffer already holds end_word() words: grow it first), back sums at 0.
  void upload(WavefrontBatchRunner& runner) const;
  // After a pass that brought texels to `samples` samples: the device's back sums into `cache`
  // (import_learned), the cache's end_pass, the back sums cleared on the device and the new front
  // tables uploaded. Returns whether the cache is still active (false: the default sampling from now on).
  bool fold_learning(WavefrontBatchRunner& runner, EmitterGuidingCache& cache, uint32_t samples);

 private:
  // The front tables and CDFs, words [front_, back_) of the section, written from `at_front` on.
  void pack_front(const EmitterGuidingCache& cache, uint32_t* at_front) const;
  // The back sums at 0 on the device.
  void clear_back(Context& context, const Buffer& buffer) const;

  std::vector<uint32_t> words_;  // the section up to its back sums, word 0 = guide buffer word base_
  size_t base_ = 0;
  size_t front_ = 0, back_ = 0, back_end_ = 0;  // section-relative
  uint32_t records_ = 0, patches_ = 0, punctual_ = 0;
  // Host-visible, kept (Context::keep_staging) for the folds' read-backs and uploads (tens of MB at
  // a million texels: a new pinned buffer per fold cost its allocation and page faults).
  Buffer staging_;
};

}  // namespace exitance::vulkan
