#include "guide_buffer.h"

#include <cstring>
#include <stdexcept>
#include <string>

namespace exitance::vulkan {

uint32_t guide_float_bits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

void upload_guide_words(WavefrontBatchRunner& runner, const std::vector<uint32_t>& words, const char* mode,
                        const char* remedy) {
  Context& context = runner.context();
  WavefrontBuffers& buffers = runner.buffers();
  const size_t bytes = words.size() * 4;
  if (uint64_t(bytes) > context.properties().limits.maxStorageBufferRange)
    throw std::runtime_error(std::string("Vulkan backend: --guiding ") + mode + ": the guide buffer (" +
                             std::to_string(bytes) + " bytes) passes the device's largest storage buffer (" + remedy + ")");
  if (buffers.probes.sh_sums.size() < bytes) {
    buffers.probes.reserve_bytes(context, bytes);
    runner.bind_buffers();
  }
  context.upload(buffers.probes.sh_sums, words.data(), bytes);
}

GuideBuffer::GuideBuffer(const GridGuidingCache& cache) : records_(cache.record_count()) {
  const std::vector<uint32_t>& index = cache.record_index();
  const size_t locator = kGuideHeaderWords;
  front_ = locator + kGuideGridWords + index.size();
  cdf_ = front_ + size_t(records_) * kGuideFrontWords;
  back_ = cdf_ + size_t(records_) * (kGuideBins + 1);
  const size_t words = back_ + size_t(records_) * kGuideBins * kGuideBackWords;
  // Learning keys are record * kGuideBins + bin in a uint, and every offset a uint word index.
  if (words >= (size_t(1) << 32) || uint64_t(records_) * kGuideBins >= 0xFFFFFFFFull)
    throw std::runtime_error("Vulkan backend: --guiding grid: " + std::to_string(records_) +
                             " guiding records do not fit the guide buffer (use fewer --guiding-grid-cells)");
  words_.assign(words, 0u);
  words_[kGuideLocatorKind] = kGuideLocatorGrid;
  words_[kGuideRecordCount] = records_;
  words_[kGuideLocatorOffset] = uint32_t(locator);
  words_[kGuideFrontOffset] = uint32_t(front_);
  words_[kGuideCdfOffset] = uint32_t(cdf_);
  words_[kGuideBackOffset] = uint32_t(back_);
  const double units = cache.fixed_units();
  uint64_t units_bits;
  std::memcpy(&units_bits, &units, 8);
  words_[kGuideFixedUnits] = uint32_t(units_bits);
  words_[kGuideFixedUnits + 1] = uint32_t(units_bits >> 32);
  words_[kGuideFixedCap] = guide_float_bits(cache.fixed_cap());
  const Vec3 origin = cache.grid_origin();
  for (int a = 0; a < 3; ++a) {
    words_[locator + size_t(a)] = guide_float_bits(origin[a]);
    words_[locator + 4 + size_t(a)] = uint32_t(cache.cells(a));
  }
  words_[locator + 3] = guide_float_bits(cache.cell_size());
  std::memcpy(&words_[locator + kGuideGridWords], index.data(), index.size() * 4);
  pack_front(cache);
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

void GuideBuffer::upload(WavefrontBatchRunner& runner) const {
  upload_guide_words(runner, words_, "grid", "use fewer --guiding-grid-cells");
}

void GuideBuffer::fold_learning(WavefrontBatchRunner& runner, GridGuidingCache& cache) {
  Context& context = runner.context();
  const Buffer& buffer = runner.buffers().probes.sh_sums;
  const size_t back_words = words_.size() - back_;
  if (back_words == 0) return;
  context.download(buffer, &words_[back_], back_words * 4, back_ * 4);
  for (uint32_t r = 0; r < records_; ++r)
    for (uint32_t b = 0; b < kGuideBins; ++b) {
      const uint32_t* w = &words_[back_ + (size_t(r) * kGuideBins + b) * kGuideBackWords];
      if (w[2] != 0) cache.import_learned(r, b, uint64_t(w[0]) | (uint64_t(w[1]) << 32), w[2]);
    }
  std::fill(words_.begin() + std::ptrdiff_t(back_), words_.end(), 0u);
  cache.swap();
  pack_front(cache);
  // Front and CDFs (adjacent) with the new table, the back sums at 0 for the next pass.
  context.upload(buffer, &words_[front_], (words_.size() - front_) * 4, front_ * 4);
}

}  // namespace exitance::vulkan
