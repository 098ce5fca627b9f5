#include "svo_guide_buffer.h"

#include "guide_buffer.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <stdexcept>
#include <string>

namespace exitance::vulkan {

SvoGuideBuffer::SvoGuideBuffer(const SvoGuidingFields& fields) { pack(fields); }

// Sections in gpu_layout.h's order: header, locator (cube, links, bin per node, record per bin and
// class), front, cdf, back (counts). Bins and records change at every rebuild, so the layout does.
void SvoGuideBuffer::pack(const SvoGuidingFields& fields) {
  const std::vector<uint32_t>& links = fields.node_links();
  const std::vector<uint32_t>& node_bin = fields.node_bin();
  const std::vector<uint32_t>& record_index = fields.record_index();
  const size_t nodes = node_bin.size();
  const size_t records = fields.record_count();
  const size_t locator = kGuideHeaderWords;
  const size_t front = locator + kGuideSvoWords + links.size() + node_bin.size() + record_index.size();
  const size_t cdf = front + records * kGuideFrontWords;
  counts_ = cdf + records * (kGuideBins + 1);
  const size_t words = counts_ + nodes * kGuideNormalClasses;
  if (words >= (size_t(1) << 32) || links.size() != 2 * nodes)
    throw std::runtime_error("Vulkan backend: --guiding svo: the octree's " + std::to_string(nodes) +
                             " nodes do not fit the guide buffer");
  words_.assign(words, 0u);
  words_[kGuideLocatorKind] = kGuideLocatorSvo;
  words_[kGuideRecordCount] = uint32_t(records);
  words_[kGuideLocatorOffset] = uint32_t(locator);
  words_[kGuideFrontOffset] = uint32_t(front);
  words_[kGuideCdfOffset] = uint32_t(cdf);
  words_[kGuideBackOffset] = uint32_t(counts_);
  const std::array<float, 3> origin = fields.origin();
  for (int a = 0; a < 3; ++a) words_[locator + size_t(a)] = guide_float_bits(origin[size_t(a)]);
  words_[locator + 3] = guide_float_bits(fields.size());
  words_[locator + 4] = fields.depth();
  words_[locator + 5] = uint32_t(nodes);
  words_[locator + 6] = fields.bin_count();
  size_t at = locator + kGuideSvoWords;
  std::copy(links.begin(), links.end(), words_.begin() + std::ptrdiff_t(at));
  at += links.size();
  std::copy(node_bin.begin(), node_bin.end(), words_.begin() + std::ptrdiff_t(at));
  at += node_bin.size();
  std::copy(record_index.begin(), record_index.end(), words_.begin() + std::ptrdiff_t(at));
  for (uint32_t r = 0; r < records; ++r) {
    const GuideVertex g = fields.vertex(r);
    uint32_t* f = &words_[front + size_t(r) * kGuideFrontWords];
    f[0] = guide_float_bits(g.guided_probability);
    f[2] = g.normal_class;
    std::memcpy(&words_[cdf + size_t(r) * (kGuideBins + 1)], g.cdf, (kGuideBins + 1) * 4);
  }
}

void SvoGuideBuffer::upload(WavefrontBatchRunner& runner) const {
  upload_guide_words(runner, words_, "svo", "use a coarser --voxel-resolution");
}

void SvoGuideBuffer::import_counts(WavefrontBatchRunner& runner, SvoGuidingFields& fields) {
  const size_t count_words = words_.size() - counts_;
  if (count_words == 0) return;
  Context& context = runner.context();
  const Buffer& buffer = runner.buffers().probes.sh_sums;
  context.download(buffer, &words_[counts_], count_words * 4, counts_ * 4);
  fields.import_counts(&words_[counts_], count_words);
  std::fill(words_.begin() + std::ptrdiff_t(counts_), words_.end(), 0u);
  context.upload(buffer, &words_[counts_], count_words * 4, counts_ * 4);
}

void SvoGuideBuffer::repack(WavefrontBatchRunner& runner, const SvoGuidingFields& fields) {
  pack(fields);
  upload(runner);
}

}  // namespace exitance::vulkan
