// Emitter guiding's data on the device (gpu_layout.h kEmitterGuide*, a section of the guide buffer
// after any other guide's): the EmitterGuidingCache's locator, patch tables and front tables packed
// as words, and its back tables' integer sums, learned by the kernels (shaders/include/
// emitter_guide.glsl) when a learning vertex's shadow ray arrives. Between passes
// fold_emitter_guide.comp folds them on the device with the cache's own fold code
// (common/emitter_guide_fold.h), so both backends build their tables the same way and a bake makes
// no host round trip but one word's read-back per fold; fold_learning_on_host is the earlier path
// (read back, EmitterGuidingCache::import_learned + end_pass, upload) for the equivalence test and
// the per-bounce mode's host-built caches.
#pragma once
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "exitance/runtime/core/emitter_guiding_cache.h"
#include "guide_fold_kernel.h"
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
  size_t end_word() const { return base_ + learned_end_; }
  // GpuParams::emitter_guide while the cache is active: the section's first word.
  uint32_t params_offset() const { return uint32_t(base_); }

  // The section onto the device (the buffer already holds end_word() words: grow it first), back
  // sums and learned sums at 0 (the cache's state before its first fold; refused after a device fold).
  void upload(WavefrontBatchRunner& runner) const;
  // After a pass that brought texels to `samples` samples: the device's back sums folded on the
  // device (`kernel`, GuideFold::Emitter) into its learned tables, front and CDFs; where past
  // EmitterGuidingCache::kEveryLearningSamples no record samples what it learned, `cache` stops, as
  // its end_pass would. Returns whether the cache is still active (false: the default sampling from now on).
  bool fold_learning(WavefrontBatchRunner& runner, GuideFoldKernel& kernel, EmitterGuidingCache& cache, uint32_t samples);
  // The same on the host: the back sums read back into `cache` (import_learned), its end_pass, the
  // back sums cleared on the device and the new front tables uploaded.
  bool fold_learning_on_host(WavefrontBatchRunner& runner, EmitterGuidingCache& cache, uint32_t samples);
  // `cache`'s report (EmitterGuidingCache::report) as the device folded it, for both drivers: with
  // an inspector (settings.inspect_emitter_guiding) the device's tables imported first and the
  // inspector called; without, the records sampling what they learned from the last device fold.
  void report(WavefrontBatchRunner& runner, EmitterGuidingCache& cache, const IntegratorSettings& settings,
              LightmapEstimate::EmitterGuidingReport& out) const;

 private:
  // After device folds: their tables into `cache` (import_folded), for the inspectors (tens of MB:
  // only when a test asks).
  void download_tables(WavefrontBatchRunner& runner, EmitterGuidingCache& cache) const;
  // The front tables and CDFs, words [front_, back_) of the section, written from `at_front` on.
  void pack_front(const EmitterGuidingCache& cache, uint32_t* at_front) const;
  // Section words [from, end) at 0 on the device.
  void clear(Context& context, const Buffer& buffer, size_t from, size_t end) const;

  std::vector<uint32_t> words_;  // the section up to its back sums, word 0 = guide buffer word base_
  size_t base_ = 0;
  size_t front_ = 0, back_ = 0, back_end_ = 0, learned_end_ = 0;  // section-relative
  bool folded_on_device_ = false;
  uint32_t sampling_records_ = 0;
  uint32_t records_ = 0, patches_ = 0, punctual_ = 0;
  // Host-visible, kept (Context::keep_staging) for the folds' read-backs and uploads (tens of MB at
  // a million texels: a new pinned buffer per fold cost its allocation and page faults).
  Buffer staging_;
};

}  // namespace exitance::vulkan
