// The runtime's progressive light probes (RefreshSession, docs/runtime.md "Probes"): the same
// estimator and random streams as ProbeDriver::bake (a probe's sample s is the same path in both),
// accumulated a stratified set (kProbeStratifiedSetSize samples) at a time, a batch of probes per
// call, round robin, so that a refresh call adds a bounded amount of probe work next to its
// lightmap passes. Its items and sums are buffers of their own (WavefrontBuffers::refresh_probe_*),
// bound only while its batches run: the texels' start points and a whole-run probe bake stay as
// they are.
//
// Light layers (docs/runtime.md "Probes"): with `light_layers` > 0 each probe also keeps its SH sums
// per light layer (light_layers.h; reduce_probes.comp), so that an edit that only scales lights'
// emission scales them exactly with 0 rays (scale_layers, scale_probe_layers.comp) and every sample
// is kept. Where the sums would pass the device's largest storage buffer, the probes keep no layers.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/integrator_settings.h"
#include "compute_kernel.h"
#include "wavefront_batch.h"

namespace exitance::vulkan {

class ProbeRefresh {
 public:
  explicit ProbeRefresh(WavefrontBatchRunner& runner);
  ~ProbeRefresh();
  // The probes refreshed from now on (their positions uploaded), their sums cleared; `light_layers`
  // as the scene's (0: none).
  void start(const std::vector<Vec3>& positions, int light_layers = 0);
  int light_layers() const { return light_layers_; }
  // An edit that only scaled lights: `factors` per light layer (rgb, w = 1 where scaled), as
  // LightLayerScaler takes them; every probe's sums scaled on the device, one submission. The
  // factors must have light_layers() entries.
  void scale_layers(const std::vector<Vec4>& factors);
  // The sums of light layer `layer` (sh_sum per probe), its totals, squared L0 sums and counts: a
  // read-back of that layer alone.
  ProbeEstimate read_layer(int layer) const;
  // Every probe's sums cleared (an edit changed the scene); the positions kept. `order` (empty: the
  // probes' own order): the order the round robin visits them in from now on, a permutation of the
  // probes (the probes nearest a local edit first); its first `priority` probes get every sample up
  // to the target before the others get any (those near the edit: the publishing rule prefers a
  // refreshed estimate with as many samples as the value it kept).
  // `change_pairs` > 0: from now on the probes' samples estimate the change of direct light from
  // that many edited punctual lights (GpuParams::changed_light_pairs; their records set on the scene
  // by a change estimate's start), pair k's change in light layer `change_layers[k]`; 0: the light.
  void clear(const std::vector<uint32_t>& order = {}, size_t priority = 0, uint32_t change_pairs = 0,
             const std::vector<uint32_t>& change_layers = {});
  uint32_t change_pairs() const { return change_pairs_; }
  // The next probes' next stratified set, round robin over the probes: as many probes as one batch
  // holds and at most `max_probes` (0: no limit), never past `target_samples` per probe. Returns the
  // rays traced (0 once every probe has its target); `refreshed`: how many probes got their set.
  // With settings.light_subpaths the set's probe paths connect to a pool of light subpaths traced
  // from `lighting` (as a probe bake's; none in a change estimate).
  uint64_t add_set(const IntegratorSettings& settings, uint32_t target_samples, size_t max_probes = 0,
                   size_t* refreshed = nullptr, const LightingScene* lighting = nullptr);
  // A read-back (waits for the device): totals, squared L0 sums and counts, and with `with_layers`
  // every light layer's sums (27 doubles per probe and layer); the light subpaths traced for them.
  ProbeEstimate read(bool with_layers = false) const;
  size_t probe_count() const { return samples_.size(); }
  // The fewest samples of a probe (every probe has whole sets).
  uint32_t least_samples() const;
  // The most samples of a probe (0: none refreshed since the last start or clear).
  uint32_t most_samples() const;

 private:
  WavefrontBatchRunner& runner_;
  std::vector<uint32_t> samples_;  // per probe, as the device's counts (back faces included)
  std::vector<uint32_t> order_;    // the round robin's order (the device's batch items)
  bool identity_order_ = true;
  size_t priority_ = 0;            // order_[0, priority_) first, to the target
  size_t next_ = 0;                // the position in order_ the next set starts at
  int light_layers_ = 0;
  uint32_t change_pairs_ = 0;
  std::vector<uint32_t> change_layers_;
  uint64_t light_subpaths_ = 0;    // traced for the sets since the last start or clear (read()'s light_subpaths)
  std::unique_ptr<ComputeKernel> scaling_;  // scale_probe_layers.comp, made at a start with layers
  Buffer factors_;
};

}  // namespace exitance::vulkan
