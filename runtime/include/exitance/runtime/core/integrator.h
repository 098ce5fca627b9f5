// The lighting backends' one interface: the CPU reference (runtime/src/cpu, Embree) and the Vulkan
// wavefront (runtime/src/vulkan) implement it over the same LightingScene, and the offline stage,
// the runtime library and the tests drive either through it.
#pragma once
#include <string>
#include <vector>

#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/integrator_settings.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual std::string backend_name() const = 0;  // "cpu", "vulkan"
  virtual std::string device_description() const = 0;

  // E/pi at every live texel of the G-buffer (path.h's estimator), with per-bounce layers.
  // Settings: spp (0 needs a time budget or a target error), time_budget_seconds,
  // target_relative_error, max_bounces, seed, recorded_bounces, russian_roulette_start,
  // safety_bounce_cap, sampling_strategy, progress. Split over several ranks (work_share), rank 0
  // gets the whole estimate; another rank's per-texel arrays may be empty (the Vulkan backend's).
  virtual LightmapEstimate bake(const TexelGBuffer& gbuffer, const IntegratorSettings& settings) const = 0;

  // A batch of rays from arbitrary origins, one set per origin: today light probes (stratified
  // sphere directions, incident radiance projected to L2 SH; ProbeEstimate). Settings: spp (0 needs
  // a time budget), time_budget_seconds (checked at stratified-set boundaries), max_bounces, seed,
  // russian_roulette_start, safety_bounce_cap, progress.
  virtual ProbeEstimate bake_probes(const std::vector<Vec3>& origins, const IntegratorSettings& settings) const = 0;

  // Whether bake(settings)'s --guiding auto may take light subpaths as its candidate (the CPU
  // backend's rule: docs/lighting-core.md "`--guiding auto`"); bake then lights the probes after the
  // texels, to follow their verdict (bake_stages.h probes_follow_texels).
  virtual bool auto_guiding_may_measure_light_subpaths(const IntegratorSettings& settings) const { return false; }
};

}  // namespace exitance
