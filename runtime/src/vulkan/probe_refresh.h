// The runtime's progressive light probes (RefreshSession, docs/runtime.md "Probes"): the same
// estimator and random streams as ProbeDriver::bake (a probe's sample s is the same path in both),
// accumulated a stratified set (kProbeStratifiedSetSize samples) at a time, a batch of probes per
// call, round robin, so that a refresh call adds a bounded amount of probe work next to its
// lightmap passes. Its items and sums are buffers of their own (WavefrontBuffers::refresh_probe_*),
// bound only while its batches run: the texels' start points and a whole-run probe bake stay as
// they are.
#pragma once
#include <cstdint>
#include <vector>

#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/integrator_settings.h"
#include "wavefront_batch.h"

namespace exitance::vulkan {

class ProbeRefresh {
 public:
  explicit ProbeRefresh(WavefrontBatchRunner& runner) : runner_(runner) {}
  // The probes refreshed from now on (their positions uploaded), their sums cleared.
  void start(const std::vector<Vec3>& positions);
  // Every probe's sums cleared (an edit changed the scene); the positions kept.
  void clear();
  // The next probes' next stratified set, round robin over the probes: as many probes as one batch
  // holds and at most `max_probes` (0: no limit), never past `target_samples` per probe. Returns the
  // rays traced (0 once every probe has its target); `refreshed`: how many probes got their set.
  uint64_t add_set(const IntegratorSettings& settings, uint32_t target_samples, size_t max_probes = 0,
                   size_t* refreshed = nullptr);
  ProbeEstimate read() const;  // a read-back: waits for the device
  size_t probe_count() const { return samples_.size(); }
  // The fewest samples of a probe (every probe has whole sets).
  uint32_t least_samples() const;
  // The most samples of a probe (0: none refreshed since the last start or clear).
  uint32_t most_samples() const;

 private:
  WavefrontBatchRunner& runner_;
  std::vector<uint32_t> samples_;  // per probe, as the device's counts (back faces included)
  size_t next_ = 0;                // the probe the next set starts at
};

}  // namespace exitance::vulkan
