#include "device_lightmaps.h"

#include <array>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "exitance_spirv/publish.h"

namespace exitance {

DeviceLightmap::DeviceLightmap(vulkan::Context& context, size_t texel_count, int layer_count, bool is_directional,
                               int light_layer_count)
    : sums(context), texels(texel_count), layers(layer_count), directional(is_directional), light_layers(light_layer_count) {
  sums.reserve(context, texels, layers + light_layers, directional);
}

size_t DeviceLightmap::bytes() const { return texels * vulkan::device_lightmap_bytes_per_texel(layers + light_layers, directional); }

namespace vulkan {
namespace {

constexpr uint32_t kBindings = 13;  // publish.comp: accumulation, previous, base, out (3 each), counts

struct PublishPush {
  uint32_t texel_count, layers, directional, mode;
};

void set_estimate(std::array<VkDescriptorBufferInfo, kBindings>& infos, uint32_t first, const TexelAccumulators& e) {
  infos[first] = {e.sums.handle(), 0, VK_WHOLE_SIZE};
  infos[first + 1] = {e.bounce_sums.handle(), 0, VK_WHOLE_SIZE};
  infos[first + 2] = {e.samples.handle(), 0, VK_WHOLE_SIZE};
}

}  // namespace

LightmapPublisher::LightmapPublisher(Context& context)
    : context_(context),
      kernel_(context, std::vector<VkDescriptorType>(kBindings, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER), sizeof(PublishPush),
              spirv_publish, sizeof(spirv_publish), 1, "publish.comp") {
  counts_ = context.create_buffer(8, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);  // read by the host, no download
  warm();
}

// One dispatch over no texels, so drivers that compile a pipeline at its first dispatch (lavapipe)
// do it here and not inside the first edit.
void LightmapPublisher::warm() {
  std::array<VkDescriptorBufferInfo, kBindings> infos{};
  for (VkDescriptorBufferInfo& info : infos) info = {counts_.handle(), 0, VK_WHOLE_SIZE};
  write_set(infos);
  VkCommandBuffer cmd = context_.begin();
  kernel_.bind(cmd);
  const PublishPush push{0, 1, 0, 0};
  kernel_.push(cmd, &push, sizeof(push));
  vkCmdDispatch(cmd, 1, 1, 1);
  context_.submit_and_wait(cmd);
}

void LightmapPublisher::write_set(const std::array<VkDescriptorBufferInfo, 13>& infos) { kernel_.write_buffers(0, infos.data(), kBindings); }

PublishedLightmap LightmapPublisher::publish(PublishMode mode, const TexelAccumulators& accumulation, const DeviceLightmap* previous,
                                             const DeviceLightmap* base, std::shared_ptr<DeviceLightmap> out,
                                             bool clear_accumulation, bool light_layers) {
  if ((mode != PublishMode::Accumulation && !previous) || (mode == PublishMode::Change && !base))
    throw std::logic_error("LightmapPublisher::publish: the mode reads an estimate that was not given");
  for (const DeviceLightmap* e : {previous, base})
    if (e && (e->texels != out->texels || e->layers != out->layers || e->directional != out->directional || e->light_layers != out->light_layers))
      throw std::logic_error("LightmapPublisher::publish: the estimates differ in texels, layers or L1 sums");
  PublishedLightmap result;
  result.lightmap = out;
  if (out->texels == 0) return result;
  std::array<VkDescriptorBufferInfo, kBindings> infos{};
  // Bindings a mode does not read point at the accumulation (read-only there, never written).
  set_estimate(infos, 0, accumulation);
  set_estimate(infos, 3, previous ? previous->sums : accumulation);
  set_estimate(infos, 6, base ? base->sums : accumulation);
  set_estimate(infos, 9, out->sums);
  infos[12] = {counts_.handle(), 0, VK_WHOLE_SIZE};
  write_set(infos);

  VkCommandBuffer cmd = context_.begin();
  clear_counters_before_compute(cmd, counts_);
  kernel_.bind(cmd);
  // The light layers follow the recorded ones: composing only the first `layers` leaves them out.
  const PublishPush push{uint32_t(out->texels), uint32_t(out->layers + (light_layers ? out->light_layers : 0)),
                         out->directional ? 1u : 0u, uint32_t(mode)};
  kernel_.push(cmd, &push, sizeof(push));
  vkCmdDispatch(cmd, uint32_t((out->texels + 63) / 64), 1, 1);
  compute_done_before_all(cmd);
  if (clear_accumulation) {
    accumulation.clear(cmd);
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                         1, &barrier, 0, nullptr, 0, nullptr);
  }
  context_.submit_and_wait(cmd);
  uint32_t counts[2] = {0, 0};
  std::memcpy(counts, counts_.mapped(), sizeof(counts));  // host-coherent: visible once the submission is done
  result.single_sample_texels = counts[0];
  result.sampled_texels = counts[1];
  return result;
}

void LightmapPublisher::upload(const LightmapEstimate& estimate, DeviceLightmap& to) {
  const size_t n = estimate.texels.size();
  if (n != to.texels || estimate.recorded_bounces != to.layers || estimate.has_sh1() != to.directional || estimate.light_layers != to.light_layers)
    throw std::invalid_argument("upload_lightmap: the estimate differs from the accumulation in texels, recorded bounces, light layers or sh1 layers");
  if (n == 0) return;
  if (estimate.bounces.size() != size_t(to.layers) * n * 3 || estimate.light_sums.size() != size_t(to.light_layers) * n * 3)
    throw std::invalid_argument("upload_lightmap: the estimate's layer sums are not sized for its texels");
  const size_t sum_doubles = n * 6 + (to.directional ? n * 9 : 0);
  context_.write_ranges(to.sums.sums, {{0, sum_doubles * 8}}, [&](char* staging) {
    double* sums = reinterpret_cast<double*>(staging);
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) sums[i * 6 + size_t(c)] = estimate.texels[i].total[c], sums[i * 6 + 3 + size_t(c)] = estimate.texels[i].total_squared[c];
    if (to.directional) std::memcpy(sums + n * 6, estimate.sh1.data(), n * 9 * 8);
  });
  context_.write_ranges(to.sums.bounce_sums, {{0, (estimate.bounces.size() + estimate.light_sums.size()) * 8}}, [&](char* staging) {
    std::memcpy(staging, estimate.bounces.data(), estimate.bounces.size() * 8);
    if (!estimate.light_sums.empty()) std::memcpy(staging + estimate.bounces.size() * 8, estimate.light_sums.data(), estimate.light_sums.size() * 8);
  });
  context_.write_ranges(to.sums.samples, {{0, n * 4}}, [&](char* staging) {
    uint32_t* samples = reinterpret_cast<uint32_t*>(staging);
    for (size_t i = 0; i < n; ++i) samples[i] = estimate.texels[i].samples;
  });
}

}  // namespace vulkan
}  // namespace exitance
