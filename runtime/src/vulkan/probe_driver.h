// Integrator::bake_probes on the wavefront: the probes are the work items (generate emits each
// probe's stratified sphere ray, shade weighs what it meets as the reference's radiance_along_ray
// and continues into the texel estimator at the hit, reduce projects each sample onto L2 SH). The
// PassScheduler's passes end on stratified sets when a time budget may stop the bake.
#pragma once
#include <vector>

#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/integrator_settings.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "wavefront_batch.h"

namespace exitance::vulkan {

// Per probe work item: 2 result slots (12 bytes each), then albedo, direction and the light layer
// slot 0 met (28 bytes; bindings.glsl kProbeExtraWords); light layers add 12 bytes each after them.
inline constexpr size_t kProbeResultBytes = 52;
inline constexpr uint32_t kProbeResultWords = uint32_t(kProbeResultBytes / 4);

// The probes' start points (position only) and the work list of probes [first, end), in order.
void upload_probe_items(Context& context, WorkItems& items, const std::vector<Vec3>& positions, size_t first, size_t end);
// `sums`' SH sums, squared L0 sums, sample counts, back-face counts and `light_layers` layers into
// `estimate`, whose sh_sum, samples and backface_hits hold one entry per probe already (a read-back).
void read_probe_sums(Context& context, const ProbeAccumulators& sums, ProbeEstimate& estimate, int light_layers = 0);

class ProbeDriver {
 public:
  explicit ProbeDriver(WavefrontBatchRunner& runner) : runner_(runner) {}
  // `lighting`: the scene the device holds, where light subpaths start (settings.light_subpaths;
  // may be null otherwise).
  ProbeEstimate bake(const std::vector<Vec3>& positions, const IntegratorSettings& settings,
                     const LightingScene* lighting = nullptr);

 private:
  void upload_probes(const std::vector<Vec3>& positions, size_t first, size_t end);

  WavefrontBatchRunner& runner_;
};

}  // namespace exitance::vulkan
