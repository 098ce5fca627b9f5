#include "wavefront_buffers.h"

#include <algorithm>

namespace exitance::vulkan {
namespace {

// Buffers a bake sizes later start at the smallest size: Vulkan buffers cannot be empty.
constexpr VkDeviceSize kPlaceholder = 16;

void grow(Context& context, Buffer& buffer, VkDeviceSize bytes) {
  if (buffer.size() < bytes) buffer = context.create_storage_buffer(bytes);
}

}  // namespace

WavefrontControl::WavefrontControl(Context& context)
    : params(context.create_storage_buffer(sizeof(GpuParams))),
      counters(context.create_storage_buffer(kCounterCount * 4)),
      readback(context.create_buffer(kCounterCount * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true)) {}

void WavefrontControl::bind(DescriptorWrites& writes) const {
  writes.set(kBindingParams, params);
  writes.set(kBindingCounters, counters);
}

PathStateBuffers::PathStateBuffers(Context& context, uint32_t paths)
    : work(context.create_storage_buffer(size_t(paths) * 4)),
      depth(context.create_storage_buffer(size_t(paths) * 4)),
      rng(context.create_storage_buffer(size_t(paths) * 16)),
      throughput(context.create_storage_buffer(size_t(paths) * 2 * 16)),  // + directional state (gpu_layout.h)
      ray_origin(context.create_storage_buffer(size_t(paths) * 16)),
      ray_direction(context.create_storage_buffer(size_t(paths) * 16)),
      hit(context.create_storage_buffer(size_t(paths) * 16)),
      shadow_rays(context.create_storage_buffer(size_t(paths) * kShadowRaysPerVertex * sizeof(ShadowRay))),
      paths(paths) {}

bool PathStateBuffers::reserve_emitter_learning(Context& context, bool light_subpaths) {
  const VkDeviceSize bytes = VkDeviceSize(paths) * (light_subpaths ? 5 : 4) * 16;
  if (throughput.size() >= bytes) return false;
  throughput = context.create_storage_buffer(bytes);
  return true;
}

bool PathStateBuffers::reserve_light_subpaths(Context& context, bool environment, bool emitter_learning) {
  bool grew = false;
  const VkDeviceSize state = VkDeviceSize(paths) * (emitter_learning ? 5 : 3) * 16;
  if (throughput.size() < state) throughput = context.create_storage_buffer(state), grew = true;
  const VkDeviceSize slots =
      VkDeviceSize(paths) * (environment ? kShadowSlotsWithEnvironmentAndConnection : kShadowSlotsWithConnection) * sizeof(ShadowRay);
  if (shadow_rays.size() < slots) shadow_rays = context.create_storage_buffer(slots), grew = true;
  return grew;
}

void PathStateBuffers::bind(DescriptorWrites& writes) const {
  writes.set(kBindingPathWork, work);
  writes.set(kBindingPathDepth, depth);
  writes.set(kBindingPathRng, rng);
  writes.set(kBindingPathThroughput, throughput);
  writes.set(kBindingPathRayOrigin, ray_origin);
  writes.set(kBindingPathRayDirection, ray_direction);
  writes.set(kBindingPathHit, hit);
  writes.set(kBindingShadowRays, shadow_rays);
}

RayQueue::RayQueue(Context& context, uint32_t paths) : entries(context.create_storage_buffer(size_t(paths) * kBytesPerPath)) {}
void RayQueue::bind(DescriptorWrites& writes) const { writes.set(kBindingRayQueue, entries); }

ShadowQueue::ShadowQueue(Context& context, uint32_t paths)
    : entries(context.create_storage_buffer(size_t(paths) * kBytesPerPath)) {}
void ShadowQueue::bind(DescriptorWrites& writes) const { writes.set(kBindingShadowQueue, entries); }

QueueDispatches::QueueDispatches(Context& context)
    : arguments(context.create_storage_buffer(16 * 4, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT)) {}
void QueueDispatches::bind(DescriptorWrites& writes) const { writes.set(kBindingIndirect, arguments); }

WorkItems::WorkItems(Context& context)
    : start_points(context.create_storage_buffer(kPlaceholder)), batch_items(context.create_storage_buffer(kPlaceholder)) {}

void WorkItems::reserve(Context& context, size_t items) {
  grow(context, start_points, items * sizeof(GpuSurfacePoint));
  grow(context, batch_items, items * 4);
}

void WorkItems::bind(DescriptorWrites& writes) const {
  writes.set(kBindingStartPoints, start_points);
  writes.set(kBindingBatchItems, batch_items);
}

SampleResults::SampleResults(Context& context) : slots(context.create_storage_buffer(kPlaceholder)) {}
void SampleResults::reserve(Context& context, VkDeviceSize bytes) { grow(context, slots, bytes); }
void SampleResults::bind(DescriptorWrites& writes) const { writes.set(kBindingResults, slots); }

TexelAccumulators::TexelAccumulators(Context& context)
    : sums(context.create_storage_buffer(kPlaceholder)),
      bounce_sums(context.create_storage_buffer(kPlaceholder)),
      samples(context.create_storage_buffer(kPlaceholder)) {}

void TexelAccumulators::reserve(Context& context, size_t texels, int layers, bool directional) {
  grow(context, sums, texels * (directional ? 6 + 9 : 6) * 8);  // + the L1 sums (gpu_layout.h)
  grow(context, bounce_sums, size_t(layers) * texels * 3 * 8);
  grow(context, samples, texels * 4);
}

void TexelAccumulators::clear(VkCommandBuffer cmd) const {
  for (const Buffer* b : {&sums, &bounce_sums, &samples}) vkCmdFillBuffer(cmd, b->handle(), 0, VK_WHOLE_SIZE, 0);
}

void TexelAccumulators::bind(DescriptorWrites& writes) const {
  writes.set(kBindingTexelSums, sums);
  writes.set(kBindingBounceSums, bounce_sums);
  writes.set(kBindingTexelSamples, samples);
}

ProbeAccumulators::ProbeAccumulators(Context& context)
    : sh_sums(context.create_storage_buffer(kPlaceholder)), counts(context.create_storage_buffer(kPlaceholder)) {}

void ProbeAccumulators::reserve(Context& context, size_t probes, int light_layers) {
  grow(context, sh_sums, sum_bytes(probes, light_layers));
  grow(context, counts, probes * 2 * 4);
}

void ProbeAccumulators::reserve_bytes(Context& context, VkDeviceSize sh_sum_bytes) { grow(context, sh_sums, sh_sum_bytes); }

void ProbeAccumulators::clear(VkCommandBuffer cmd) const {
  for (const Buffer* b : {&sh_sums, &counts}) vkCmdFillBuffer(cmd, b->handle(), 0, VK_WHOLE_SIZE, 0);
}

void ProbeAccumulators::bind(DescriptorWrites& writes) const {
  writes.set(kBindingProbeShSums, sh_sums);
  writes.set(kBindingProbeCounts, counts);
}

LightPool::LightPool(Context& context) : words(context.create_storage_buffer(kPlaceholder)) {}

bool LightPool::reserve(Context& context, uint64_t vertices) {
  const VkDeviceSize bytes = (VkDeviceSize(kLightPoolVertexWord) + VkDeviceSize(vertices) * kLightVertexWords) * 4;
  if (words.size() >= bytes) return false;
  words = context.create_storage_buffer(bytes);
  return true;
}

uint32_t LightPool::capacity() const {
  const VkDeviceSize word_count = words.size() / 4;
  if (word_count <= kLightPoolVertexWord) return 0;
  return uint32_t(std::min<VkDeviceSize>((word_count - kLightPoolVertexWord) / kLightVertexWords, 0xFFFFFFFFu));
}

void LightPool::bind(DescriptorWrites& writes) const { writes.set(kBindingLightSubpaths, words); }

WavefrontBuffers::WavefrontBuffers(Context& context, uint32_t path_count)
    : control(context),
      paths(context, path_count),
      rays(context, path_count),
      shadows(context, path_count),
      dispatches(context),
      items(context),
      results(context),
      texels(context),
      probes(context),
      refresh_probe_items(context),
      refresh_probe_sums(context),
      light_pool(context) {}

void WavefrontBuffers::bind(DescriptorWrites& writes) const {
  control.bind(writes);
  paths.bind(writes);
  rays.bind(writes);
  shadows.bind(writes);
  dispatches.bind(writes);
  (probe_refresh_bound ? refresh_probe_items : items).bind(writes);
  results.bind(writes);
  texels.bind(writes);
  (probe_refresh_bound ? refresh_probe_sums : probes).bind(writes);
  light_pool.bind(writes);
}

}  // namespace exitance::vulkan
