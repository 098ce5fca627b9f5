#include "probe_refresh.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <optional>
#include <stdexcept>

#include "exitance_spirv/scale_probe_layers.h"
#include "light_subpath_pools.h"
#include "probe_driver.h"

namespace exitance::vulkan {
namespace {

struct ScalePush {
  uint32_t probe_count, scaled;
};

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

ProbeRefresh::ProbeRefresh(WavefrontBatchRunner& runner) : runner_(runner) {}
ProbeRefresh::~ProbeRefresh() = default;

void ProbeRefresh::start(const std::vector<Vec3>& positions, int light_layers) {
  if (positions.size() >= (1ull << 31)) throw std::runtime_error("Vulkan backend: too many probes");
  Context& context = runner_.context();
  WavefrontBuffers& buffers = runner_.buffers();
  samples_.assign(positions.size(), 0);
  next_ = 0;
  light_subpaths_ = 0;
  // Layers only where their sums fit one storage buffer binding and a batch holds a set's work.
  const VkDeviceSize limit = context.properties().limits.maxStorageBufferRange;
  light_layers_ = std::max(0, light_layers);
  if (ProbeAccumulators::sum_bytes(positions.size(), light_layers_) > limit ||
      VkDeviceSize(kProbeStratifiedSetSize) * (kProbeResultBytes + 12 * size_t(light_layers_)) > limit)
    light_layers_ = 0;
  if (positions.empty()) return;
  buffers.refresh_probe_items.reserve(context, positions.size());
  buffers.refresh_probe_sums.reserve(context, positions.size(), light_layers_);
  upload_probe_items(context, buffers.refresh_probe_items, positions, 0, positions.size());
  order_.resize(positions.size());
  for (size_t i = 0; i < order_.size(); ++i) order_[i] = uint32_t(i);
  identity_order_ = true;
  if (light_layers_ > 0 && !scaling_) {
    scaling_ = std::make_unique<ComputeKernel>(context, std::vector<VkDescriptorType>(2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER),
                                               uint32_t(sizeof(ScalePush)), spirv_scale_probe_layers,
                                               sizeof(spirv_scale_probe_layers), 1, "scale_probe_layers.comp");
    factors_ = context.create_buffer(sizeof(Vec4) * size_t(light_layers_), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
    // One dispatch over no probe, so a driver that compiles at the first dispatch (lavapipe) does
    // it here and not inside the first edit.
    const std::array<VkDescriptorBufferInfo, 2> infos{{{buffers.refresh_probe_sums.sh_sums.handle(), 0, VK_WHOLE_SIZE},
                                                       {factors_.handle(), 0, VK_WHOLE_SIZE}}};
    scaling_->write_buffers(0, infos.data(), 2);
    VkCommandBuffer cmd = context.begin();
    scaling_->bind(cmd, 0);
    const ScalePush push{0, 0};
    scaling_->push(cmd, &push, sizeof(push));
    vkCmdDispatch(cmd, 1, 1, 1);
    context.submit_and_wait(cmd);
  }
  clear();
}

void ProbeRefresh::scale_layers(const std::vector<Vec4>& factors) {
  if (light_layers_ == 0 || factors.size() != size_t(light_layers_))
    throw std::logic_error("ProbeRefresh::scale_layers: factors for " + std::to_string(factors.size()) + " layers, the probes keep " +
                           std::to_string(light_layers_));
  std::vector<Vec4> scaled;
  for (size_t l = 0; l < factors.size(); ++l)
    if (factors[l].w != 0) scaled.push_back(Vec4(factors[l].x, factors[l].y, factors[l].z, float(l)));
  if (scaled.empty() || samples_.empty()) return;
  Context& context = runner_.context();
  std::memcpy(factors_.mapped(), scaled.data(), scaled.size() * sizeof(Vec4));  // host-coherent
  // The sums buffer may have grown since the descriptor was written.
  const std::array<VkDescriptorBufferInfo, 2> infos{{{runner_.buffers().refresh_probe_sums.sh_sums.handle(), 0, VK_WHOLE_SIZE},
                                                     {factors_.handle(), 0, VK_WHOLE_SIZE}}};
  scaling_->write_buffers(0, infos.data(), 2);
  VkCommandBuffer cmd = context.begin();
  writes_visible_to_compute(cmd);
  scaling_->bind(cmd, 0);
  const ScalePush push{uint32_t(samples_.size()), uint32_t(scaled.size())};
  scaling_->push(cmd, &push, sizeof(push));
  vkCmdDispatch(cmd, uint32_t((samples_.size() + 63) / 64), 1, 1);
  compute_done_before_all(cmd);
  context.submit_and_wait(cmd);
}

ProbeEstimate ProbeRefresh::read_layer(int layer) const {
  if (layer < 0 || layer >= light_layers_) throw std::logic_error("ProbeRefresh::read_layer: no layer " + std::to_string(layer));
  const size_t count = samples_.size();
  ProbeEstimate estimate;
  estimate.sh_sum.assign(count, std::array<double, 27>{});
  estimate.samples.assign(count, 0);
  estimate.backface_hits.assign(count, 0);
  if (count == 0) return estimate;
  Context& context = runner_.context();
  const ProbeAccumulators& sums = runner_.buffers().refresh_probe_sums;
  std::vector<uint32_t> counts(count * 2);
  context.download(sums.counts, counts.data(), counts.size() * 4);
  context.download(sums.sh_sums, estimate.sh_sum.data(), count * 27 * 8,
                   VkDeviceSize(count) * (ProbeAccumulators::kSumsPerProbe + 27 * size_t(layer)) * 8);
  for (size_t i = 0; i < count; ++i) estimate.samples[i] = counts[i * 2], estimate.backface_hits[i] = counts[i * 2 + 1];
  return estimate;
}

void ProbeRefresh::clear(const std::vector<uint32_t>& order, size_t priority, uint32_t change_pairs,
                         const std::vector<uint32_t>& change_layers) {
  if (change_pairs > kMaxChangedLightPairs || (change_pairs > 0 && change_layers.size() != change_pairs))
    throw std::logic_error("ProbeRefresh::clear: a change of at most kMaxChangedLightPairs lights, each with its layer");
  change_pairs_ = change_pairs;
  change_layers_ = change_layers;
  light_subpaths_ = 0;
  std::fill(samples_.begin(), samples_.end(), 0u);
  next_ = 0;
  priority_ = order.empty() ? 0 : std::min(priority, order.size());
  if (samples_.empty()) return;
  Context& context = runner_.context();
  if (!order.empty() || !identity_order_) {
    if (!order.empty() && order.size() != samples_.size()) throw std::logic_error("ProbeRefresh::clear: an order of another probe count");
    order_ = order;
    if (order_.empty()) {
      order_.resize(samples_.size());
      for (size_t i = 0; i < order_.size(); ++i) order_[i] = uint32_t(i);
    }
    identity_order_ = order.empty();
    context.upload_at_next_submission(runner_.buffers().refresh_probe_items.batch_items, order_.data(), order_.size() * 4);
  }
  // The order's upload and the sums' clear run at the start of the next submission (an edit's
  // publish, or the next probe set): no round trip of their own inside an edit.
  const ProbeAccumulators& sums = runner_.buffers().refresh_probe_sums;
  context.record_at_next_submission([&sums](VkCommandBuffer cmd) { sums.clear(cmd); });
}

uint64_t ProbeRefresh::add_set(const IntegratorSettings& settings, uint32_t target_samples, size_t max_probes,
                               size_t* refreshed, const LightingScene* lighting) {
  if (refreshed) *refreshed = 0;
  const size_t count = samples_.size();
  if (count == 0) return 0;
  // Probes [next_, end) share one sample count (round robin): one batch of their next set (the last
  // one cut at the target, as a whole-run bake's last pass is). The priority probes first, round
  // robin among themselves until the last of them (the fewest samples) has the target, then the others.
  size_t lo = 0, hi = count;
  if (priority_ > 0) {
    if (samples_[order_[priority_ - 1]] < target_samples) hi = priority_;
    else lo = priority_;
  }
  if (lo >= hi) return 0;
  if (next_ < lo || next_ >= hi) next_ = lo;
  const uint32_t first_sample = samples_[order_[next_]];
  if (first_sample >= target_samples) return 0;  // round robin: the rest have as many
  const uint32_t set = std::min(kProbeStratifiedSetSize, target_samples - first_sample);
  const size_t max_work = runner_.work_items_per_batch(kProbeResultBytes + 12 * size_t(light_layers_));
  size_t per_batch = std::max<size_t>(1, max_work / set);
  if (max_probes > 0) per_batch = std::min(per_batch, max_probes);
  const size_t end = std::min(hi, next_ + per_batch);
  Context& context = runner_.context();
  runner_.buffers().results.reserve(context, std::max<size_t>(max_work, size_t(set)) * (kProbeResultBytes + 12 * size_t(light_layers_)));
  GpuParams params = runner_.bake_params(settings, 1, uint32_t(count));
  params.probe_spp = target_samples;
  params.light_layers = uint32_t(light_layers_);
  params.punctual_layers = runner_.scene().punctual_light_layers();
  params.light_result_words = kProbeResultWords;
  params.changed_light_pairs = change_pairs_;
  for (size_t k = 0; k < change_layers_.size(); ++k) params.changed_light_layers[k] = change_layers_[k];
  const size_t result_bytes = kProbeResultBytes + 12 * size_t(light_layers_);
  // Light subpaths: the set's probe paths connect from each probe ray's first hit to a pool of their
  // own, as a probe bake's batches (probe_driver.cpp); not in a change estimate, whose paths add only
  // the edited lights' direct light.
  std::optional<LightSubpathPools> light_pools;
  if (settings.light_subpaths && change_pairs_ == 0) {
    if (!lighting) throw std::logic_error("Vulkan backend: light subpaths for refreshed probes without the integrator's scene");
    light_pools.emplace(runner_, *lighting, settings, max_work, params);
  }
  BatchTotals totals;
  {
    const ProbeRefreshBinding bound(runner_);
    if (light_pools) light_pools->before_batch(params, double(end - next_) * set);
    runner_.run(params, {uint32_t(next_), uint32_t(end - next_), first_sample, set}, result_bytes, kProbeBatch, totals);
    if (light_pools) light_pools->after_batch(totals, params);
  }
  light_subpaths_ += totals.light_subpaths;
  for (size_t i = next_; i < end; ++i) samples_[order_[i]] += set;
  if (refreshed) *refreshed = end - next_;
  next_ = end;
  return totals.rays();
}

ProbeEstimate ProbeRefresh::read(bool with_layers) const {
  const size_t count = samples_.size();
  ProbeEstimate estimate;
  estimate.sh_sum.assign(count, std::array<double, 27>{});
  estimate.samples.assign(count, 0);
  estimate.backface_hits.assign(count, 0);
  read_probe_sums(runner_.context(), runner_.buffers().refresh_probe_sums, estimate, with_layers ? light_layers_ : 0);
  estimate.light_subpaths = light_subpaths_;
  return estimate;
}

uint32_t ProbeRefresh::most_samples() const {
  return samples_.empty() ? 0 : *std::max_element(samples_.begin(), samples_.end());
}

uint32_t ProbeRefresh::least_samples() const {
  return samples_.empty() ? 0 : *std::min_element(samples_.begin(), samples_.end());
}

}  // namespace exitance::vulkan
