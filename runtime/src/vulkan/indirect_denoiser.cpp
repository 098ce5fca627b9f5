#include "indirect_denoiser.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <stdexcept>
#include <string>

#include "exitance_spirv/denoise_indirect.h"

namespace exitance::vulkan {
namespace {

constexpr uint32_t kBindings = 12;  // denoise_indirect.comp: in (3), out (3), texels, where, pages, pixels, indirect, counts
constexpr uint32_t kNone = 0xffffffffu;
constexpr size_t kRecordFloats = 8;  // [position, texel size], [normal, 0]

struct DenoisePush {
  uint32_t texel_count, layers;
  int32_t radius;
  uint32_t pass, totals_only;
};

void write_record(float* r, const LiveTexel& t) {
  r[0] = t.position.x, r[1] = t.position.y, r[2] = t.position.z, r[3] = t.world_texel_size;
  r[4] = t.geometric_normal.x, r[5] = t.geometric_normal.y, r[6] = t.geometric_normal.z, r[7] = 0;
}

}  // namespace

IndirectDenoiser::IndirectDenoiser(Context& context, const TexelGBuffer& gbuffer)
    : context_(context),
      texels_(gbuffer.texels.size()),
      kernel_(context, std::vector<VkDescriptorType>(kBindings, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER), sizeof(DenoisePush),
              spirv_denoise_indirect, sizeof(spirv_denoise_indirect), 1, "denoise_indirect.comp") {
  const size_t n = texels_;
  std::vector<uint32_t> where(n * 2), pages, pixels;
  for (const AtlasPage& page : gbuffer.pages) {
    if (page.width >= 65536 || page.height >= 65536)
      throw std::invalid_argument("IndirectDenoiser: a page of " + std::to_string(page.width) + " x " + std::to_string(page.height) +
                                  " texels (at most 65535 a side)");
    pages.insert(pages.end(), {uint32_t(pixels.size()), uint32_t(page.width), uint32_t(page.height), 0u});
    page_sizes_.insert(page_sizes_.end(), {uint32_t(page.width), uint32_t(page.height)});
    pixels.resize(pixels.size() + size_t(page.width) * size_t(page.height), kNone);
  }
  for (size_t i = 0; i < n; ++i) {
    const LiveTexel& t = gbuffer.texels[i];
    where[i * 2] = t.page;
    where[i * 2 + 1] = t.x | (t.y << 16);
    pixels[pages[size_t(t.page) * 4] + size_t(t.y) * size_t(gbuffer.pages[t.page].width) + t.x] = uint32_t(i);
  }
  // Empty buffers are 16 bytes: a descriptor needs a buffer.
  records_buffer_ = context.create_storage_buffer(std::max<size_t>(n * kRecordFloats * 4, 16));
  where_ = context.create_storage_buffer(std::max<size_t>(where.size() * 4, 16));
  pages_ = context.create_storage_buffer(std::max<size_t>(pages.size() * 4, 16));
  pixels_ = context.create_storage_buffer(std::max<size_t>(pixels.size() * 4, 16));
  indirect_ = context.create_storage_buffer(std::max<size_t>(n * 32, 16));
  counts_ = context.create_buffer(8, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  std::vector<Context::RangeWrite> writes;
  if (n > 0) {
    writes.push_back({&records_buffer_, {{0, n * kRecordFloats * 4}}, [&](char* staging) {
                        for (size_t i = 0; i < n; ++i) write_record(reinterpret_cast<float*>(staging) + i * kRecordFloats, gbuffer.texels[i]);
                      }});
    writes.push_back(Context::RangeWrite::whole(where_, where.data(), where.size() * 4));
  }
  if (!pages.empty()) writes.push_back(Context::RangeWrite::whole(pages_, pages.data(), pages.size() * 4));
  if (!pixels.empty()) writes.push_back(Context::RangeWrite::whole(pixels_, pixels.data(), pixels.size() * 4));
  if (!writes.empty()) context.write_ranges(writes);
}

bool IndirectDenoiser::fits(const TexelGBuffer& gbuffer) const {
  if (gbuffer.texels.size() != texels_ || gbuffer.pages.size() * 2 != page_sizes_.size()) return false;
  for (size_t p = 0; p < gbuffer.pages.size(); ++p)
    if (uint32_t(gbuffer.pages[p].width) != page_sizes_[p * 2] || uint32_t(gbuffer.pages[p].height) != page_sizes_[p * 2 + 1]) return false;
  return true;
}

void IndirectDenoiser::update_texels(const TexelGBuffer& gbuffer, const std::vector<uint32_t>& texels) {
  if (texels.empty()) return;
  for (uint32_t i : texels)
    if (i >= texels_ || i >= gbuffer.texels.size())
      throw std::out_of_range("IndirectDenoiser: texel " + std::to_string(i) + " of " + std::to_string(texels_));
  // A moved texel keeps its atlas place (same G-buffer layout): only its world record changes. The
  // runs' records are written from the G-buffer, the unchanged ones in joined gaps as they are.
  std::vector<uint32_t> sorted = texels;
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  constexpr size_t kRecord = kRecordFloats * 4;
  const std::vector<std::pair<uint32_t, uint32_t>> runs = record_runs(sorted, kRecord);
  context_.write_ranges(records_buffer_, byte_ranges(runs, kRecord), [&](char* staging) {
    float* out = reinterpret_cast<float*>(staging);
    for (const auto& [first, end] : runs)
      for (uint32_t i = first; i < end; ++i, out += kRecordFloats) write_record(out, gbuffer.texels[i]);
  });
}

DeviceDenoiseCounts IndirectDenoiser::filter(const DeviceLightmap& in, DeviceLightmap& out, int radius, bool totals_only) {
  if (in.texels != texels_ || out.texels != texels_ || out.layers != in.layers || out.directional || out.light_layers != 0)
    throw std::invalid_argument("IndirectDenoiser: the estimates are not shaped for the G-buffer's texels and layers");
  DeviceDenoiseCounts counts;
  if (texels_ == 0) return counts;
  const std::array<VkDescriptorBufferInfo, kBindings> infos{{
      {in.sums.sums.handle(), 0, VK_WHOLE_SIZE},
      {in.sums.bounce_sums.handle(), 0, VK_WHOLE_SIZE},
      {in.sums.samples.handle(), 0, VK_WHOLE_SIZE},
      {out.sums.sums.handle(), 0, VK_WHOLE_SIZE},
      {out.sums.bounce_sums.handle(), 0, VK_WHOLE_SIZE},
      {out.sums.samples.handle(), 0, VK_WHOLE_SIZE},
      {records_buffer_.handle(), 0, VK_WHOLE_SIZE},
      {where_.handle(), 0, VK_WHOLE_SIZE},
      {pages_.handle(), 0, VK_WHOLE_SIZE},
      {pixels_.handle(), 0, VK_WHOLE_SIZE},
      {indirect_.handle(), 0, VK_WHOLE_SIZE},
      {counts_.handle(), 0, VK_WHOLE_SIZE},
  }};
  kernel_.write_buffers(0, infos.data(), kBindings);

  VkCommandBuffer cmd = context_.begin();
  clear_counters_before_compute(cmd, counts_);
  kernel_.bind(cmd);
  const uint32_t groups = uint32_t((texels_ + 63) / 64);
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  for (uint32_t pass = 0; pass < 2; ++pass) {
    const DenoisePush push{uint32_t(texels_), uint32_t(in.layers), radius, pass, totals_only ? 1u : 0u};
    kernel_.push(cmd, &push, sizeof(push));
    vkCmdDispatch(cmd, groups, 1, 1);
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                         &barrier, 0, nullptr, 0, nullptr);
  }
  context_.submit_and_wait(cmd);
  uint32_t read[2] = {0, 0};
  std::memcpy(read, counts_.mapped(), sizeof(read));  // host-coherent: visible once the submission is done
  counts.texels = read[0];
  counts.neighbours = read[1];
  return counts;
}

}  // namespace exitance::vulkan
