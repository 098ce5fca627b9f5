#include "emitter_guide_buffer.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <stdexcept>
#include <string>

#include "exitance/formats/huge_pages.h"
#include "exitance/runtime/core/parallel_chunks.h"
#include "guide_buffer.h"

namespace exitance::vulkan {

std::unique_ptr<EmitterGuidingCache> emitter_guide_for_device(const std::shared_ptr<const LightingScene>& lighting,
                                                              const GpuScene& device_scene, const TexelGBuffer& gbuffer,
                                                              const IntegratorSettings& settings) {
  if (!settings.emitter_guiding) return nullptr;
  if (!lighting) throw std::logic_error("Vulkan backend: emitter guiding without the integrator's scene");
  // Their powers may differ after an emission edit: the mixture stays unbiased, as its densities
  // read the device's CDF.
  if (lighting->emitter_triangles != device_scene.emitter_triangles() || lighting->punctual_count() != device_scene.punctual_count())
    throw std::invalid_argument("Vulkan backend: --emitter-guiding on: the device's scene was edited since the integrator was made; "
                                "emitter guiding bakes the scene it was made on");
  // Folded on the device unless asked otherwise (LightmapDriver, BounceLayerDriver): then the
  // host's cache keeps no back tables or learned sums (~100 MB at a million texels, first touched
  // in its setup).
  return EmitterGuidingCache::for_bake(*lighting, gbuffer, settings,
                                       settings.guide_fold_on_host || settings.bounce_caches_on_host);
}

EmitterGuideBuffer::EmitterGuideBuffer(const EmitterGuidingCache& cache, size_t base)
    : base_(std::max<size_t>(base, kGuideHeaderWords)),
      records_(cache.record_count()),
      patches_(cache.patch_count()),
      punctual_(cache.punctual_count()) {
  const GuideGridLocator& locator = cache.locator();
  const EmitterPatches& patches = cache.patches();
  const std::vector<uint32_t>& triangle_emitter = cache.triangle_emitter();
  // Section-relative offsets, in the order of gpu_layout.h's description.
  const size_t locator_at = kEmitterGuideHeaderWords;
  const size_t emitter_patch_at = locator_at + kGuideGridWords + locator.record_index().size();
  const size_t patch_emitters_at = emitter_patch_at + patches.emitter_patch.size();
  const size_t triangle_emitter_at = patch_emitters_at + patches.patch_emitters.size();
  const size_t default_at = triangle_emitter_at + triangle_emitter.size();
  const size_t punctual_default_at = default_at + patches.default_probability.size();
  const size_t cluster_first_at = punctual_default_at + cache.punctual_default().size();
  front_ = cluster_first_at + patches.cluster_first.size();
  const size_t cdf_at = front_ + size_t(records_) * kEmitterGuideFrontWords;
  const size_t punctual_cdf_at = cdf_at + (patches_ > 0 ? size_t(records_) * (patches_ + 1) : 0);
  back_ = punctual_cdf_at + (punctual_ > 0 ? size_t(records_) * (punctual_ + 1) : 0);
  const size_t punctual_back_at = back_ + size_t(records_) * patches_ * kGuideBackWords;
  back_end_ = punctual_back_at + size_t(records_) * punctual_ * kEmitterGuidePunctualBackWords;
  const size_t punctual_learned_at = back_end_ + size_t(records_) * patches_ * kEmitterGuideLearnedWords;
  learned_end_ = punctual_learned_at + size_t(records_) * punctual_ * kEmitterGuidePunctualLearnedWords;
  if (base_ + learned_end_ >= (size_t(1) << 32))
    throw std::runtime_error("Vulkan backend: --emitter-guiding on: " + std::to_string(records_) + " records of " +
                             std::to_string(patches_) + " patches do not fit the guide buffer (use fewer --guiding-grid-cells)");
  // Zeros up to the back sums, which live on the device alone (zeroed there, read back by the
  // folds): tens of MB, first touched in huge pages where the kernel allows.
  formats::resize_in_huge_pages(words_, back_);
  auto absolute = [&](size_t at) { return uint32_t(base_ + at); };
  words_[kEmitterGuideLocator] = absolute(locator_at);
  words_[kEmitterGuideRecords] = records_;
  words_[kEmitterGuidePatches] = patches_;
  words_[kEmitterGuidePunctual] = punctual_;
  words_[kEmitterGuideEmitterPatch] = absolute(emitter_patch_at);
  words_[kEmitterGuidePatchEmitters] = absolute(patch_emitters_at);
  words_[kEmitterGuideTriangleEmitter] = absolute(triangle_emitter_at);
  words_[kEmitterGuideFront] = absolute(front_);
  words_[kEmitterGuideCdf] = absolute(cdf_at);
  words_[kEmitterGuidePunctualCdf] = absolute(punctual_cdf_at);
  words_[kEmitterGuideBack] = absolute(back_);
  words_[kEmitterGuidePunctualBack] = absolute(punctual_back_at);
  words_[kEmitterGuideDefault] = absolute(default_at);
  words_[kEmitterGuidePunctualDefault] = absolute(punctual_default_at);
  words_[kEmitterGuideClusterFirst] = absolute(cluster_first_at);
  words_[kEmitterGuideClusters] = patches.cluster_count();
  words_[kEmitterGuideMix] = guide_float_bits(cache.mix());
  words_[kEmitterGuideLearned] = absolute(back_end_);
  words_[kEmitterGuidePunctualLearned] = absolute(punctual_learned_at);
  pack_fixed_point(cache.fixed_units(), cache.fixed_cap(), &words_[kEmitterGuideFixedUnits]);
  pack_grid_locator(locator, &words_[locator_at]);
  std::copy(patches.emitter_patch.begin(), patches.emitter_patch.end(), words_.begin() + std::ptrdiff_t(emitter_patch_at));
  std::copy(patches.patch_emitters.begin(), patches.patch_emitters.end(), words_.begin() + std::ptrdiff_t(patch_emitters_at));
  std::copy(triangle_emitter.begin(), triangle_emitter.end(), words_.begin() + std::ptrdiff_t(triangle_emitter_at));
  for (size_t k = 0; k < patches.default_probability.size(); ++k)
    words_[default_at + k] = guide_float_bits(patches.default_probability[k]);
  for (size_t i = 0; i < cache.punctual_default().size(); ++i)
    words_[punctual_default_at + i] = guide_float_bits(cache.punctual_default()[i]);
  std::copy(patches.cluster_first.begin(), patches.cluster_first.end(), words_.begin() + std::ptrdiff_t(cluster_first_at));
  sampling_records_ = cache.records_sampling_learned();
  pack_front(cache, &words_[front_]);
}

void EmitterGuideBuffer::pack_front(const EmitterGuidingCache& cache, uint32_t* at_front) const {
  const size_t cdf_at = words_[kEmitterGuideCdf] - base_ - front_;
  const size_t punctual_cdf_at = words_[kEmitterGuidePunctualCdf] - base_ - front_;
  for_each_chunk(
      records_,
      [&](size_t first, size_t end) {
        for (size_t r = first; r < end; ++r) {
          const EmitterGuide g = cache.vertex(uint32_t(r));
          uint32_t* f = at_front + r * kEmitterGuideFrontWords;
          f[0] = guide_float_bits(g.guided_probability);
          f[1] = guide_float_bits(g.punctual_guided_probability);
          if (patches_ > 0) std::memcpy(at_front + cdf_at + r * (patches_ + 1), g.cdf, (size_t(patches_) + 1) * 4);
          if (punctual_ > 0) std::memcpy(at_front + punctual_cdf_at + r * (punctual_ + 1), g.punctual_cdf, (size_t(punctual_) + 1) * 4);
        }
      },
      64);
}

void EmitterGuideBuffer::upload(WavefrontBatchRunner& runner) const {
  Context& context = runner.context();
  const Buffer& buffer = runner.buffers().probes.sh_sums;
  if (buffer.size() < end_word() * 4) throw std::logic_error("EmitterGuideBuffer::upload: the guide buffer was not grown");
  // The learned section lives on the device alone: zeros are the cache's tables only before any fold.
  if (folded_on_device_) throw std::logic_error("EmitterGuideBuffer::upload: would discard the device's folded tables");
  context.upload(buffer, words_.data(), words_.size() * 4, base_ * 4);
  clear(context, buffer, back_, learned_end_);
}

void EmitterGuideBuffer::clear(Context& context, const Buffer& buffer, size_t from, size_t end) const {
  if (end == from) return;
  VkCommandBuffer cmd = context.begin();
  vkCmdFillBuffer(cmd, buffer.handle(), (base_ + from) * 4, (end - from) * 4, 0);
  context.submit_and_wait(cmd);
}

bool EmitterGuideBuffer::fold_learning(WavefrontBatchRunner& runner, GuideFoldKernel& kernel, EmitterGuidingCache& cache,
                                       uint32_t samples) {
  folded_on_device_ = true;
  sampling_records_ = kernel.fold_emitters(runner.buffers().probes.sh_sums, records_, uint32_t(base_));
  // EmitterGuidingCache::end_pass's rule on the device's count.
  if (samples >= EmitterGuidingCache::kEveryLearningSamples && sampling_records_ == 0) {
    cache.deactivate();
    return false;
  }
  return true;
}

void EmitterGuideBuffer::download_tables(WavefrontBatchRunner& runner, EmitterGuidingCache& cache) const {
  if (!folded_on_device_ || records_ == 0) return;
  Context& context = runner.context();
  const Buffer& buffer = runner.buffers().probes.sh_sums;
  // Front and CDFs are adjacent; the learned section follows the back sums.
  std::vector<uint32_t> tables(back_ - front_), learned(learned_end_ - back_end_);
  context.download(buffer, tables.data(), tables.size() * 4, (base_ + front_) * 4);
  if (!learned.empty()) context.download(buffer, learned.data(), learned.size() * 4, (base_ + back_end_) * 4);
  const size_t cdf_at = words_[kEmitterGuideCdf] - base_ - front_;
  const size_t punctual_cdf_at = words_[kEmitterGuidePunctualCdf] - base_ - front_;
  const size_t punctual_learned_at = words_[kEmitterGuidePunctualLearned] - base_ - back_end_;
  // One thread: the cache allocates its learned tables on the first import (an inspector's path).
  std::vector<double> sums(patches_), punctual_sums(punctual_);
  std::vector<uint32_t> samples(patches_);
  std::vector<float> cdf(patches_ + 1), punctual_cdf(punctual_ + 1);
  for (size_t r = 0; r < records_; ++r) {
    for (uint32_t k = 0; k < patches_; ++k) {
      const uint32_t* w = &learned[(r * patches_ + k) * kEmitterGuideLearnedWords];
      sums[k] = std::bit_cast<double>(uint64_t(w[0]) | (uint64_t(w[1]) << 32));
      samples[k] = w[2];
    }
    for (uint32_t i = 0; i < punctual_; ++i) {
      const uint32_t* w = &learned[punctual_learned_at + (r * punctual_ + i) * kEmitterGuidePunctualLearnedWords];
      punctual_sums[i] = std::bit_cast<double>(uint64_t(w[0]) | (uint64_t(w[1]) << 32));
    }
    if (patches_ > 0) std::memcpy(cdf.data(), tables.data() + cdf_at + r * (patches_ + 1), cdf.size() * 4);
    if (punctual_ > 0)
      std::memcpy(punctual_cdf.data(), tables.data() + punctual_cdf_at + r * (punctual_ + 1), punctual_cdf.size() * 4);
    const uint32_t* f = &tables[r * kEmitterGuideFrontWords];
    cache.import_folded(uint32_t(r), sums.data(), samples.data(), cdf.data(), std::bit_cast<float>(f[0]),
                        punctual_sums.data(), punctual_cdf.data(), std::bit_cast<float>(f[1]));
  }
}

void EmitterGuideBuffer::report(WavefrontBatchRunner& runner, EmitterGuidingCache& cache, const IntegratorSettings& settings,
                                LightmapEstimate::EmitterGuidingReport& out) const {
  if (settings.inspect_emitter_guiding) download_tables(runner, cache);
  cache.report(out);
  if (folded_on_device_ && cache.active()) out.records_sampling_learned = sampling_records_;
  if (settings.inspect_emitter_guiding) settings.inspect_emitter_guiding(cache);
}

bool EmitterGuideBuffer::fold_learning_on_host(WavefrontBatchRunner& runner, EmitterGuidingCache& cache, uint32_t samples) {
  Context& context = runner.context();
  const Buffer& buffer = runner.buffers().probes.sh_sums;
  context.keep_staging(staging_, std::max(back_end_ - back_, back_ - front_) * 4);
  const size_t punctual_back_at = words_[kEmitterGuidePunctualBack] - base_;
  // The back sums imported straight from the read-back's mapping, records on all cores (the cache's
  // back tables add atomically; each record's rows are its own).
  context.read_back_ranges(buffer, {{(base_ + back_) * 4, (back_end_ - back_) * 4}}, [&](const char* mapped) {
    const uint32_t* back = reinterpret_cast<const uint32_t*>(mapped);  // section word back_ at 0
    for_each_chunk(
        records_,
        [&](size_t first, size_t end) {
          for (size_t r = first; r < end; ++r) {
            for (uint32_t k = 0; k < patches_; ++k) {
              const uint32_t* w = &back[(r * patches_ + k) * kGuideBackWords];
              if (w[2] != 0) cache.import_learned(uint32_t(r), k, uint64_t(w[0]) | (uint64_t(w[1]) << 32), w[2]);
            }
            for (uint32_t i = 0; i < punctual_; ++i) {
              const uint32_t* w = &back[punctual_back_at - back_ + (r * punctual_ + i) * kEmitterGuidePunctualBackWords];
              if (w[0] != 0 || w[1] != 0) cache.import_learned_punctual(uint32_t(r), i, uint64_t(w[0]) | (uint64_t(w[1]) << 32));
            }
          }
        },
        16);
  }, &staging_);
  cache.end_pass(samples);
  sampling_records_ = cache.records_sampling_learned();
  clear(context, buffer, back_, back_end_);  // at 0 on the device too, for the next pass
  if (!cache.active()) return false;
  // Front and CDFs (adjacent sections) with the new tables; words_ keeps them too, for a whole
  // upload after the buffer grows (BounceLayerDriver's host-built caches).
  pack_front(cache, &words_[front_]);
  context.write_ranges(buffer, {{(base_ + front_) * 4, (back_ - front_) * 4}},
                       [&](char* mapped) { std::memcpy(mapped, &words_[front_], (back_ - front_) * 4); }, &staging_);
  return true;
}

}  // namespace exitance::vulkan
