#include "lightmap_driver.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <stdexcept>

#include "exitance/runtime/core/pass_scheduler.h"

namespace exitance::vulkan {
namespace {

constexpr int kMaxRecordedBounces = 16;

}  // namespace

void LightmapDriver::upload_texels(const TexelGBuffer& gbuffer, const std::vector<uint32_t>& work_list) {
  Context& context = runner_.context();
  WavefrontBuffers& buffers = runner_.buffers();
  std::vector<GpuSurfacePoint> texels(gbuffer.texels.size());
  for (size_t i = 0; i < texels.size(); ++i) {
    const LiveTexel& t = gbuffer.texels[i];
    texels[i] = {Vec4(t.position, 0.0f), Vec4(t.geometric_normal, 0.0f), Vec4(t.shading_normal, 0.0f)};
  }
  context.upload(buffers.items.start_points, texels.data(), texels.size() * sizeof(GpuSurfacePoint));
  context.upload(buffers.items.batch_items, work_list.data(), work_list.size() * 4);
  VkCommandBuffer cmd = context.begin();
  buffers.texels.clear(cmd);
  context.submit_and_wait(cmd);
}

std::vector<uint32_t> LightmapDriver::unconverged(const std::vector<uint32_t>& work_list, size_t texel_count, double target) {
  const TexelAccumulators& texels = runner_.buffers().texels;
  std::vector<double> sums(texel_count * 6);
  std::vector<uint32_t> samples(texel_count);
  runner_.context().download(texels.sums, sums.data(), sums.size() * 8);
  runner_.context().download(texels.samples, samples.data(), samples.size() * 4);
  std::vector<uint32_t> still;
  for (uint32_t i : work_list) {
    LightmapEstimate one;  // the reference's test (estimates.h)
    one.texels.resize(1);
    for (int c = 0; c < 3; ++c)
      one.texels[0].total[c] = sums[i * 6 + size_t(c)], one.texels[0].total_squared[c] = sums[i * 6 + 3 + size_t(c)];
    one.texels[0].samples = samples[i];
    if (!one.relative_error_below(0, target)) still.push_back(i);
  }
  return still;
}

LightmapEstimate LightmapDriver::bake(const TexelGBuffer& gbuffer, const IntegratorSettings& settings) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const size_t texel_count = gbuffer.texels.size();
  LightmapEstimate estimate;
  estimate.recorded_bounces = std::clamp(settings.recorded_bounces, 1, kMaxRecordedBounces);
  const int K = estimate.recorded_bounces;
  estimate.texels.resize(texel_count);
  estimate.bounces.assign(size_t(K) * texel_count * 3, 0.0);
  runner_.statistics().clear();
  if (texel_count == 0) return estimate;
  if (texel_count >= (1ull << 31)) throw std::runtime_error("Vulkan backend: too many texels");

  // Per work item, result slots 0..K of RGB floats; enough items per batch to keep every path slot
  // busy between drains, within the largest storage buffer.
  const size_t result_bytes = size_t(K + 1) * 12;
  const size_t max_work = runner_.work_items_per_batch(result_bytes);
  Context& context = runner_.context();
  WavefrontBuffers& buffers = runner_.buffers();
  buffers.items.reserve(context, texel_count);
  buffers.texels.reserve(context, texel_count, K);
  buffers.results.reserve(context, max_work * result_bytes);
  runner_.bind_buffers();
  std::vector<uint32_t> work_list(texel_count);
  for (size_t i = 0; i < texel_count; ++i) work_list[i] = uint32_t(i);
  upload_texels(gbuffer, work_list);

  GpuParams params = runner_.bake_params(settings, uint32_t(K), uint32_t(texel_count));
  BatchTotals totals;
  const uint32_t spp_limit = settings.spp == 0 ? std::numeric_limits<uint32_t>::max() : settings.spp;
  PassPolicy policy;
  // Untimed: as many samples per batch as fill the work items; a budget or target error: ramped passes.
  policy.largest_pass = uint32_t(std::max<size_t>(1, max_work / std::min(texel_count, max_work)));
  policy.ramp = settings.time_budget_seconds > 0 || settings.target_relative_error > 0;
  PassScheduler passes(settings, policy);
  uint32_t first = 0, pass = 0;
  while (!work_list.empty() && passes.next_pass(first, pass)) {
    const uint32_t chunk = uint32_t(std::min(work_list.size(), max_work));
    pass = std::min<uint32_t>(pass, uint32_t(std::max<size_t>(1, max_work / chunk)));
    for (size_t offset = 0; offset < work_list.size(); offset += chunk) {
      const uint32_t n = uint32_t(std::min<size_t>(chunk, work_list.size() - offset));
      runner_.run(params, {uint32_t(offset), n, first, pass}, result_bytes, kTexelBatch, totals);
    }
    const uint32_t done = first + pass;
    if (settings.target_relative_error > 0 && done >= 16 && done < spp_limit) {
      std::vector<uint32_t> still = unconverged(work_list, texel_count, settings.target_relative_error);
      if (still.size() != work_list.size()) {
        work_list = std::move(still);
        if (!work_list.empty()) context.upload(buffers.items.batch_items, work_list.data(), work_list.size() * 4);
      }
    }
    passes.finish_pass(totals.rays(), work_list.empty());
  }

  std::vector<double> sums(texel_count * 6);
  std::vector<uint32_t> samples(texel_count);
  context.download(buffers.texels.sums, sums.data(), sums.size() * 8);
  context.download(buffers.texels.samples, samples.data(), samples.size() * 4);
  context.download(buffers.texels.bounce_sums, estimate.bounces.data(), estimate.bounces.size() * 8);
  for (size_t i = 0; i < texel_count; ++i) {
    TexelAccumulator& a = estimate.texels[i];
    for (int c = 0; c < 3; ++c) {
      a.total[c] = sums[i * 6 + size_t(c)];
      a.total_squared[c] = sums[i * 6 + 3 + size_t(c)];
      a.direct[c] = estimate.bounces[i * 3 + size_t(c)];  // layer 0 is the direct light
    }
    a.samples = samples[i];
  }
  estimate.rays = totals.rays();
  estimate.nonfinite_samples = totals.nonfinite;
  estimate.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  runner_.record_statistics(totals, kTexelBatch);
  return estimate;
}

}  // namespace exitance::vulkan
