#include "probe_driver.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <optional>
#include <stdexcept>

#include "exitance/runtime/core/pass_scheduler.h"
#include "light_subpath_pools.h"
#include "exitance/runtime/core/work_share.h"

namespace exitance::vulkan {
void upload_probe_items(Context& context, WorkItems& items, const std::vector<Vec3>& positions, size_t first, size_t end) {
  std::vector<GpuSurfacePoint> records(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) records[i].position = Vec4(positions[i], 0.0f);
  context.upload(items.start_points, records.data(), records.size() * sizeof(GpuSurfacePoint));
  std::vector<uint32_t> order(end - first);
  for (size_t i = first; i < end; ++i) order[i - first] = uint32_t(i);
  if (!order.empty()) context.upload(items.batch_items, order.data(), order.size() * 4);
}

void read_probe_sums(Context& context, const ProbeAccumulators& accumulators, ProbeEstimate& estimate, int light_layers) {
  const size_t count = estimate.sh_sum.size();
  if (count == 0) return;
  // Totals and squares first in the buffer, then the layers: light_layers 0 reads the former alone.
  std::vector<double> sums(size_t(ProbeAccumulators::sum_bytes(count, light_layers) / 8));
  std::vector<uint32_t> counts(count * 2);
  context.download(accumulators.sh_sums, sums.data(), sums.size() * 8);
  context.download(accumulators.counts, counts.data(), counts.size() * 4);
  estimate.l0_square_sum.assign(count, {});
  for (size_t i = 0; i < count; ++i) {
    std::copy(sums.begin() + std::ptrdiff_t(i * 27), sums.begin() + std::ptrdiff_t(i * 27 + 27), estimate.sh_sum[i].begin());
    for (size_t c = 0; c < 3; ++c) estimate.l0_square_sum[i][c] = sums[count * 27 + i * 3 + c];
    estimate.samples[i] = counts[i * 2];
    estimate.backface_hits[i] = counts[i * 2 + 1];
  }
  estimate.light_layers = light_layers;
  estimate.light_sh_sum.assign(count * size_t(light_layers), {});
  const double* layers = sums.data() + count * ProbeAccumulators::kSumsPerProbe;
  for (size_t k = 0; k < estimate.light_sh_sum.size(); ++k) std::copy(layers + k * 27, layers + k * 27 + 27, estimate.light_sh_sum[k].begin());
}

// Start points with the position only, and the work list: the probes [first, end) in order.
void ProbeDriver::upload_probes(const std::vector<Vec3>& positions, size_t first, size_t end) {
  Context& context = runner_.context();
  WavefrontBuffers& buffers = runner_.buffers();
  upload_probe_items(context, buffers.items, positions, first, end);
  buffers.items.owner = WorkItems::Owner::Probes;
  VkCommandBuffer cmd = context.begin();
  buffers.probes.clear(cmd);
  context.submit_and_wait(cmd);
}

ProbeEstimate ProbeDriver::bake(const std::vector<Vec3>& positions, const IntegratorSettings& settings,
                                const LightingScene* lighting) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const size_t probe_count = positions.size();
  ProbeEstimate estimate;
  estimate.sh_sum.assign(probe_count, std::array<double, 27>{});
  estimate.samples.assign(probe_count, 0);
  estimate.backface_hits.assign(probe_count, 0);
  runner_.statistics().clear();
  if (probe_count == 0) return estimate;
  if (probe_count >= (1ull << 31)) throw std::runtime_error("Vulkan backend: too many probes");

  const size_t max_work = runner_.work_items_per_batch(kProbeResultBytes);
  Context& context = runner_.context();
  WavefrontBuffers& buffers = runner_.buffers();
  buffers.items.reserve(context, probe_count);
  buffers.probes.reserve(context, probe_count);
  buffers.results.reserve(context, max_work * kProbeResultBytes);
  runner_.bind_buffers();
  // Split over processes (core/work_share.h): this rank's device traces its contiguous range of the
  // probes (global indices: the same random streams); the sums are gathered at the end.
  WorkShare* share = distributed(settings.work_share);
  const std::vector<size_t> bounds = share ? split_by_cost(probe_count, {}, share->ranks()) : std::vector<size_t>{};
  const size_t own_begin = share ? bounds[size_t(share->rank())] : 0;
  const size_t own_end = share ? bounds[size_t(share->rank()) + 1] : probe_count;
  const size_t own_count = own_end - own_begin;
  upload_probes(positions, own_begin, own_end);

  GpuParams params = runner_.bake_params(settings, 1, uint32_t(probe_count));  // slot 0: what the probe ray meets; 1: E/pi at its hit
  params.probe_spp = settings.spp == 0 ? std::numeric_limits<uint32_t>::max() : settings.spp;
  // Light subpaths: each batch's probe paths connect from each probe ray's first hit (its fixed x_0,
  // as a texel is) to a pool of their own.
  std::optional<LightSubpathPools> light_pools;
  if (settings.light_subpaths) {
    if (!lighting) throw std::logic_error("Vulkan backend: light subpaths for probes without the integrator's scene");
    light_pools.emplace(runner_, *lighting, settings, max_work, params);
  }
  BatchTotals totals;
  const uint32_t chunk = uint32_t(std::min(probe_count, max_work));
  PassPolicy policy;
  policy.largest_pass = uint32_t(std::max<size_t>(1, max_work / chunk));
  // With a time budget, passes end on stratified-set boundaries and the budget is only checked
  // there, so a stopped run never leaves a set's strata out (as the reference).
  policy.stratified_set = kProbeStratifiedSetSize;
  PassScheduler passes(settings, policy);
  uint32_t first = 0, pass = 0;
  while (passes.next_pass(first, pass)) {
    const auto pass_start = Clock::now();
    for (size_t offset = 0; offset < own_count; offset += chunk) {
      const uint32_t n = uint32_t(std::min<size_t>(chunk, own_count - offset));
      if (light_pools) light_pools->before_batch(params, double(n) * pass);
      runner_.run(params, {uint32_t(offset), n, first, pass}, kProbeResultBytes, kProbeBatch, totals);
      if (light_pools) light_pools->after_batch(totals, params);
    }
    if (share) {
      share->work.probe_samples += uint64_t(own_count) * pass;
      share->work.seconds += std::chrono::duration<double>(Clock::now() - pass_start).count();
    }
    passes.finish_pass(totals.rays());
  }

  read_probe_sums(context, buffers.probes, estimate);
  estimate.rays = totals.rays();
  estimate.nonfinite_samples = totals.nonfinite;
  estimate.light_subpaths = totals.light_subpaths;
  estimate.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  runner_.record_statistics(totals, kProbeBatch);
  if (settings.work_share) settings.work_share->work.rays += estimate.rays;
  if (share) {
    allgather_items(*share, estimate.sh_sum.data(), 1, bounds);
    allgather_items(*share, estimate.samples.data(), 1, bounds);
    allgather_items(*share, estimate.backface_hits.data(), 1, bounds);
    estimate.rays = share->sum(estimate.rays);
    estimate.nonfinite_samples = share->sum(estimate.nonfinite_samples);
  } else if (settings.work_share) {
    for (uint32_t n : estimate.samples) settings.work_share->work.probe_samples += n;
    settings.work_share->work.seconds += estimate.seconds;
  }
  return estimate;
}

}  // namespace exitance::vulkan
