#include "probe_refresh.h"

#include <algorithm>
#include <stdexcept>

#include "probe_driver.h"

namespace exitance::vulkan {
namespace {

// Binds the refresh's items and sums for as long as it lives, then the bake's again (also when a
// batch throws), so a lightmap pass after it finds its own buffers bound.
class ProbeRefreshBinding {
 public:
  explicit ProbeRefreshBinding(WavefrontBatchRunner& runner) : runner_(runner) {
    runner_.buffers().probe_refresh_bound = true;
    runner_.bind_buffers();
  }
  ~ProbeRefreshBinding() {
    runner_.buffers().probe_refresh_bound = false;
    runner_.bind_buffers();
  }
  ProbeRefreshBinding(const ProbeRefreshBinding&) = delete;
  ProbeRefreshBinding& operator=(const ProbeRefreshBinding&) = delete;

 private:
  WavefrontBatchRunner& runner_;
};

}  // namespace

void ProbeRefresh::start(const std::vector<Vec3>& positions) {
  if (positions.size() >= (1ull << 31)) throw std::runtime_error("Vulkan backend: too many probes");
  Context& context = runner_.context();
  WavefrontBuffers& buffers = runner_.buffers();
  samples_.assign(positions.size(), 0);
  next_ = 0;
  if (positions.empty()) return;
  buffers.refresh_probe_items.reserve(context, positions.size());
  buffers.refresh_probe_sums.reserve(context, positions.size());
  upload_probe_items(context, buffers.refresh_probe_items, positions, 0, positions.size());
  clear();
}

void ProbeRefresh::clear() {
  std::fill(samples_.begin(), samples_.end(), 0u);
  next_ = 0;
  if (samples_.empty()) return;
  Context& context = runner_.context();
  VkCommandBuffer cmd = context.begin();
  runner_.buffers().refresh_probe_sums.clear(cmd);
  context.submit_and_wait(cmd);
}

uint64_t ProbeRefresh::add_set(const IntegratorSettings& settings, uint32_t target_samples, size_t max_probes,
                               size_t* refreshed) {
  if (refreshed) *refreshed = 0;
  const size_t count = samples_.size();
  if (count == 0) return 0;
  // Probes [next_, end) share one sample count (round robin): one batch of their next set (the last
  // one cut at the target, as a whole-run bake's last pass is).
  if (next_ >= count) next_ = 0;
  const uint32_t first_sample = samples_[next_];
  if (first_sample >= target_samples) return 0;  // round robin: the rest have as many
  const uint32_t set = std::min(kProbeStratifiedSetSize, target_samples - first_sample);
  const size_t max_work = runner_.work_items_per_batch(kProbeResultBytes);
  size_t per_batch = std::max<size_t>(1, max_work / set);
  if (max_probes > 0) per_batch = std::min(per_batch, max_probes);
  const size_t end = std::min(count, next_ + per_batch);
  Context& context = runner_.context();
  runner_.buffers().results.reserve(context, std::max<size_t>(max_work, size_t(set)) * kProbeResultBytes);
  GpuParams params = runner_.bake_params(settings, 1, uint32_t(count));
  params.probe_spp = target_samples;
  BatchTotals totals;
  {
    const ProbeRefreshBinding bound(runner_);
    runner_.run(params, {uint32_t(next_), uint32_t(end - next_), first_sample, set}, kProbeResultBytes, kProbeBatch, totals);
  }
  for (size_t i = next_; i < end; ++i) samples_[i] += set;
  if (refreshed) *refreshed = end - next_;
  next_ = end;
  return totals.rays();
}

ProbeEstimate ProbeRefresh::read() const {
  const size_t count = samples_.size();
  ProbeEstimate estimate;
  estimate.sh_sum.assign(count, std::array<double, 27>{});
  estimate.samples.assign(count, 0);
  estimate.backface_hits.assign(count, 0);
  read_probe_sums(runner_.context(), runner_.buffers().refresh_probe_sums, estimate);
  return estimate;
}

uint32_t ProbeRefresh::most_samples() const {
  return samples_.empty() ? 0 : *std::max_element(samples_.begin(), samples_.end());
}

uint32_t ProbeRefresh::least_samples() const {
  return samples_.empty() ? 0 : *std::min_element(samples_.begin(), samples_.end());
}

}  // namespace exitance::vulkan
