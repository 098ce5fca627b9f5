// Grid guiding's data on the device (gpu_layout.h kBindingGuide, in the probe SH sums' binding):
// the GridGuidingCache's locator, front table and learned radiance packed as the guide buffer's
// sections, and its back table's integer sums, learned by the kernels (shaders/include/guide.glsl)
// and folded on the device between learning passes (fold_guide.comp: GridGuidingCache::swap's code,
// common/guide_fold.h), so both backends build the same tables from the same sums and the device's
// bake makes no host round trip while it learns. The table comes back to the cache once, at the end.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "exitance/runtime/core/grid_guiding_cache.h"
#include "guide_fold_kernel.h"
#include "wavefront_batch.h"

namespace exitance::vulkan {

// A float's bits as one guide-buffer word.
uint32_t guide_float_bits(float f);
// A grid locator as kGuideLocatorGrid's words from `out` (kGuideGridWords: origin, cell size, cells;
// then per (cell, normal class) its record): what guide.glsl guide_grid_record_at reads, for grid
// guiding's section and emitter guiding's.
void pack_grid_locator(const GuideGridLocator& locator, uint32_t* out);
// common/guide_learning.h guide_fixed_point's scale (a double as lo, hi words) and target cap: the
// three words from `out` (kGuideFixedUnits, kGuideFixedCap; kEmitterGuideFixedUnits, kEmitterGuideFixedCap).
void pack_fixed_point(double units, float cap, uint32_t* out);
// Every guide layout's words onto the device, in the guide binding (the probe SH sums' buffer, grown
// and rebound when too small). `mode` and `remedy` complete the error when the device's largest
// storage buffer is too small. `zero_words` zeros follow `words`, cleared on the device.
void upload_guide_words(WavefrontBatchRunner& runner, const std::vector<uint32_t>& words, const char* mode,
                        const char* remedy, size_t zero_words = 0);

class GuideBuffer {
 public:
  // Lays out and packs the sections of `cache` (its front table as it is now).
  explicit GuideBuffer(const GridGuidingCache& cache);
  // The header alone, no locator (every record lookup finds none): for --guiding auto with light
  // subpaths as its candidate, which reads only the auto sections (add_auto_sections). The grid's
  // tables, never sampled there, were most of the buffer (the open city at 1.5 texels/m: 148 MB).
  GuideBuffer();

  // The whole buffer onto the device (growing and rebinding the binding), back sums at 0.
  void upload(WavefrontBatchRunner& runner) const;
  // After a learning pass, on the device: the back sums folded into the learned section and
  // cleared, the front table and CDFs rebuilt (one waited dispatch, nothing read back).
  void fold_learning(WavefrontBatchRunner& runner, GuideFoldKernel& kernel);
  // The same on the host (IntegratorSettings::guide_fold_on_host: the equivalence test, benches):
  // the back sums read back into `cache` (import_learned), its swap, the back sums cleared on the
  // device and the new front table uploaded. `cache` then holds the table.
  void fold_learning_on_host(WavefrontBatchRunner& runner, GridGuidingCache& cache);
  // The device's learned table into `cache` (GridGuidingCache::import_tables): for what reads the
  // cache after a bake (IntegratorSettings::inspect_guiding).
  void download_tables(WavefrontBatchRunner& runner, GridGuidingCache& cache) const;

  size_t bytes() const { return (words_.size() + sum_words_) * 4; }

  // --guiding auto (gpu_layout.h kGuidingAuto): appends the per-texel strategy words and the zeroed
  // strategy sums (kAutoSumDoubles x 2 per texel) after the grid's sections. Before upload().
  void add_auto_sections(const std::vector<uint32_t>& texel_words, uint32_t pilot, uint32_t statistics_from);
  // The strategy words onto the device again (after the choice).
  void upload_auto_words(WavefrontBatchRunner& runner, const std::vector<uint32_t>& texel_words);
  // The device's strategy sums, [texel][unguided, guided][kAutoSumDoubles].
  std::vector<double> download_auto_sums(WavefrontBatchRunner& runner) const;

 private:
  void pack_front(const GridGuidingCache& cache);

  std::vector<uint32_t> words_;
  size_t front_ = 0, cdf_ = 0, back_ = 0, learned_ = 0;  // first words of the sections
  size_t auto_texels_ = 0, auto_sums_ = 0, auto_texel_count_ = 0;
  size_t sum_words_ = 0;  // the pilot sums' words after words_ (zeros, cleared on the device)
  uint32_t records_ = 0;
  float mix_ = 0;  // the cache's guided share of a learned record
};

}  // namespace exitance::vulkan
