#include "guide_buffer.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "exitance/runtime/core/parallel_chunks.h"

namespace exitance::vulkan {

uint32_t guide_float_bits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

static_assert(kGuideFixedCap == kGuideFixedUnits + 2 && kEmitterGuideFixedCap == kEmitterGuideFixedUnits + 2,
              "pack_fixed_point writes the scale's two words, then the cap");

void pack_grid_locator(const GuideGridLocator& locator, uint32_t* out) {
  const Vec3 origin = locator.origin();
  for (int a = 0; a < 3; ++a) {
    out[a] = guide_float_bits(origin[a]);
    out[4 + a] = uint32_t(locator.cells(a));
  }
  out[3] = guide_float_bits(locator.cell_size());
  out[7] = 0;
  std::copy(locator.record_index().begin(), locator.record_index().end(), out + kGuideGridWords);
}

void pack_fixed_point(double units, float cap, uint32_t* out) {
  uint64_t units_bits;
  std::memcpy(&units_bits, &units, 8);
  out[0] = uint32_t(units_bits);
  out[1] = uint32_t(units_bits >> 32);
  out[2] = guide_float_bits(cap);
}

// The zeros after `words` cleared on the device (--guiding auto's pilot sums: 112 B per texel, not
// worth building on the host and copying across at a million texels).
void upload_guide_words(WavefrontBatchRunner& runner, const std::vector<uint32_t>& words, const char* mode,
                        const char* remedy, size_t zero_words) {
  Context& context = runner.context();
  WavefrontBuffers& buffers = runner.buffers();
  const size_t bytes = (words.size() + zero_words) * 4;
  if (uint64_t(bytes) > context.properties().limits.maxStorageBufferRange)
    throw std::runtime_error(std::string("Vulkan backend: --guiding ") + mode + ": the guide buffer (" +
                             std::to_string(bytes) + " bytes) passes the device's largest storage buffer (" + remedy + ")");
  if (buffers.probes.sh_sums.size() < bytes) {
    buffers.probes.reserve_bytes(context, bytes);
    runner.bind_buffers();
  }
  context.upload(buffers.probes.sh_sums, words.data(), words.size() * 4);
  if (zero_words == 0) return;
  VkCommandBuffer cmd = context.begin();
  vkCmdFillBuffer(cmd, buffers.probes.sh_sums.handle(), words.size() * 4, zero_words * 4, 0);
  context.submit_and_wait(cmd);
}

GuideBuffer::GuideBuffer(const GridGuidingCache& cache) : records_(cache.record_count()) {
  const std::vector<uint32_t>& index = cache.record_index();
  const size_t locator = kGuideHeaderWords;
  front_ = locator + kGuideGridWords + index.size();
  cdf_ = front_ + size_t(records_) * kGuideFrontWords;
  back_ = cdf_ + size_t(records_) * (kGuideBins + 1);
  learned_ = back_ + size_t(records_) * kGuideBins * kGuideBackWords;
  const size_t words = learned_ + size_t(records_) * kGuideBins * kGuideLearnedWords;
  // Learning keys are record * kGuideBins + bin in a uint, and every offset a uint word index.
  if (words >= (size_t(1) << 32) || uint64_t(records_) * kGuideBins >= 0xFFFFFFFFull)
    throw std::runtime_error("Vulkan backend: --guiding grid: " + std::to_string(records_) +
                             " guiding records do not fit the guide buffer (use fewer --guiding-grid-cells)");
  words_.assign(words, 0u);
  mix_ = cache.mix();
  words_[kGuideLocatorKind] = kGuideLocatorGrid;
  words_[kGuideRecordCount] = records_;
  words_[kGuideLocatorOffset] = uint32_t(locator);
  words_[kGuideFrontOffset] = uint32_t(front_);
  words_[kGuideCdfOffset] = uint32_t(cdf_);
  words_[kGuideBackOffset] = uint32_t(back_);
  words_[kGuideLearnedOffset] = uint32_t(learned_);
  pack_fixed_point(cache.fixed_units(), cache.fixed_cap(), &words_[kGuideFixedUnits]);
  pack_grid_locator(cache.locator(), &words_[locator]);
  pack_front(cache);
  for (uint32_t r = 0; r < records_; ++r)
    for (uint32_t b = 0; b < kGuideBins; ++b) {
      uint32_t* l = &words_[learned_ + (size_t(r) * kGuideBins + b) * kGuideLearnedWords];
      l[0] = guide_float_bits(cache.radiance(r)[b]);
      l[1] = guide_float_bits(cache.weight(r)[b]);
    }
}

void GuideBuffer::pack_front(const GridGuidingCache& cache) {
  for (uint32_t r = 0; r < records_; ++r) {
    const GuideVertex g = cache.vertex(r);
    uint32_t* f = &words_[front_ + size_t(r) * kGuideFrontWords];
    f[0] = guide_float_bits(g.guided_probability);
    f[1] = guide_float_bits(cache.expected_cosine_radiance(r));
    f[2] = g.normal_class;
    f[3] = 0;
    std::memcpy(&words_[cdf_ + size_t(r) * (kGuideBins + 1)], g.cdf, (kGuideBins + 1) * 4);
  }
}

GuideBuffer::GuideBuffer() : words_(kGuideHeaderWords, 0u) {}  // kGuideLocatorKind 0: no locator, no records

void GuideBuffer::upload(WavefrontBatchRunner& runner) const {
  upload_guide_words(runner, words_, "grid", "use fewer --guiding-grid-cells", sum_words_);
}

void GuideBuffer::fold_learning(WavefrontBatchRunner& runner, GuideFoldKernel& kernel) {
  kernel.fold_grid(runner.buffers().probes.sh_sums, records_, mix_);
}

void GuideBuffer::fold_learning_on_host(WavefrontBatchRunner& runner, GridGuidingCache& cache) {
  Context& context = runner.context();
  const Buffer& buffer = runner.buffers().probes.sh_sums;
  const size_t back_words = learned_ - back_;
  if (back_words == 0) return;
  context.download(buffer, &words_[back_], back_words * 4, back_ * 4);
  // Records on all cores (the cache's back table adds atomically; each record's bins are its own).
  for_each_chunk(
      records_,
      [&](size_t first, size_t end) {
        for (size_t r = first; r < end; ++r)
          for (uint32_t b = 0; b < kGuideBins; ++b) {
            const uint32_t* w = &words_[back_ + (r * kGuideBins + b) * kGuideBackWords];
            if (w[2] != 0) cache.import_learned(uint32_t(r), b, uint64_t(w[0]) | (uint64_t(w[1]) << 32), w[2]);
          }
      },
      64);
  std::fill(words_.begin() + std::ptrdiff_t(back_), words_.begin() + std::ptrdiff_t(learned_), 0u);
  cache.swap();
  pack_front(cache);
  // The back sums at 0 on the device for the next pass; front and CDFs (adjacent) with the new
  // table. The learned section is not read on this path (the cache holds it).
  VkCommandBuffer cmd = context.begin();
  vkCmdFillBuffer(cmd, buffer.handle(), back_ * 4, back_words * 4, 0);
  context.submit_and_wait(cmd);
  context.upload(buffer, &words_[front_], (back_ - front_) * 4, front_ * 4);
}

void GuideBuffer::download_tables(WavefrontBatchRunner& runner, GridGuidingCache& cache) const {
  if (records_ == 0) return;
  Context& context = runner.context();
  const Buffer& buffer = runner.buffers().probes.sh_sums;
  // Front and CDFs are adjacent; the learned section follows the back sums.
  std::vector<uint32_t> front_and_cdf(back_ - front_), learned(size_t(records_) * kGuideBins * kGuideLearnedWords);
  context.download(buffer, front_and_cdf.data(), front_and_cdf.size() * 4, front_ * 4);
  context.download(buffer, learned.data(), learned.size() * 4, learned_ * 4);
  std::vector<float> radiance(size_t(records_) * kGuideBins), weight(radiance.size()), expected(records_), probability(records_);
  for (size_t i = 0; i < radiance.size(); ++i) {
    std::memcpy(&radiance[i], &learned[i * kGuideLearnedWords], 4);
    std::memcpy(&weight[i], &learned[i * kGuideLearnedWords + 1], 4);
  }
  for (uint32_t r = 0; r < records_; ++r) {
    std::memcpy(&probability[r], &front_and_cdf[size_t(r) * kGuideFrontWords], 4);
    std::memcpy(&expected[r], &front_and_cdf[size_t(r) * kGuideFrontWords + 1], 4);
  }
  static_assert(sizeof(float) == 4);
  const float* cdf = reinterpret_cast<const float*>(&front_and_cdf[cdf_ - front_]);
  cache.import_tables(radiance.data(), weight.data(), cdf, expected.data(), probability.data());
}

void GuideBuffer::add_auto_sections(const std::vector<uint32_t>& texel_words, uint32_t pilot, uint32_t statistics_from) {
  auto_texel_count_ = texel_words.size();
  auto_texels_ = words_.size();
  auto_sums_ = (auto_texels_ + texel_words.size() + 1) & ~size_t(1);  // doubles: an even word
  const size_t words = auto_sums_ + auto_texel_count_ * 2 * kAutoSumDoubles * 2;
  if (words >= (size_t(1) << 32))
    throw std::runtime_error("Vulkan backend: --guiding auto: " + std::to_string(auto_texel_count_) +
                             " texels' strategy sums do not fit the guide buffer (use a lower --texel-density)");
  words_.resize(auto_sums_, 0u);  // the sums after them are cleared on the device (upload)
  sum_words_ = words - auto_sums_;
  std::copy(texel_words.begin(), texel_words.end(), words_.begin() + std::ptrdiff_t(auto_texels_));
  words_[kGuideAutoTexels] = uint32_t(auto_texels_);
  words_[kGuideAutoSums] = uint32_t(auto_sums_);
  words_[kGuideAutoPilot] = pilot;
  words_[kGuideAutoStatisticsFrom] = statistics_from;
}

void GuideBuffer::upload_auto_words(WavefrontBatchRunner& runner, const std::vector<uint32_t>& texel_words) {
  if (texel_words.size() != auto_texel_count_) throw std::logic_error("GuideBuffer: strategy words of another atlas");
  std::copy(texel_words.begin(), texel_words.end(), words_.begin() + std::ptrdiff_t(auto_texels_));
  runner.context().upload(runner.buffers().probes.sh_sums, texel_words.data(), texel_words.size() * 4, auto_texels_ * 4);
}

std::vector<double> GuideBuffer::download_auto_sums(WavefrontBatchRunner& runner) const {
  std::vector<double> sums(auto_texel_count_ * 2 * kAutoSumDoubles);
  if (!sums.empty())
    runner.context().download(runner.buffers().probes.sh_sums, sums.data(), sums.size() * 8, auto_sums_ * 4);
  return sums;
}

}  // namespace exitance::vulkan
