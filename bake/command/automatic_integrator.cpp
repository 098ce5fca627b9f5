#include "exitance/bake/command/automatic_integrator.h"

#include "exitance/runtime/core/work_share.h"

namespace exitance {

IntegratorMode automatic_integrator(const BakeOptions& options, const Integrator& backend) {
  if (backend.backend_name() != "cpu") return IntegratorMode::Path;
  if (options.lighting.directional != DirectionalMode::Off) return IntegratorMode::Path;
  if (options.lighting.light_layers) return IntegratorMode::Path;  // the per-bounce passes keep no split by light
  // A guide the user names guides path tracing, so auto picks it (auto guiding does not ask for it).
  if (options.lighting.guiding == GuidingMode::Grid || options.lighting.guiding == GuidingMode::Svo) return IntegratorMode::Path;
  if (options.adaptive_request == AdaptiveRequest::On) return IntegratorMode::Path;
  if (options.lighting.light_subpaths) return IntegratorMode::Path;  // connections are path-tracing strategies
  return IntegratorMode::Bounces;
}

GuidingMode automatic_guiding(const BakeOptions& options, const Integrator& backend) {
  if (options.lighting.guiding != GuidingMode::Auto) return options.lighting.guiding;
  if (options.lighting.light_subpaths) return GuidingMode::Off;  // not combined with guided vertices yet
  // Vulkan: only when asked for, since its pilot costs and a guided GPU bake still loses at equal
  // time on the sample scenes (its learning passes, bench/results/guiding-gpu.md).
  const bool backend_measures = backend.backend_name() == "cpu" || (backend.backend_name() == "vulkan" && options.guiding_auto_given);
  const bool measured_choice = backend_measures && options.lighting.integrator == IntegratorMode::Path &&
                               !distributed(options.lighting.work_share);
  return measured_choice ? GuidingMode::Auto : GuidingMode::Off;
}

bool automatic_emitter_guiding(const BakeOptions& options, const Integrator& backend) {
  return backend.backend_name() == "cpu" && !distributed(options.lighting.work_share);
}

BakeOptions with_integrator_decided(const BakeOptions& options, const Integrator& backend) {
  BakeOptions decided = options;
  if (options.integrator_auto) decided.lighting.integrator = automatic_integrator(options, backend);
  decided.lighting.guiding = automatic_guiding(decided, backend);
  if (options.emitter_guiding_auto) decided.lighting.emitter_guiding = automatic_emitter_guiding(decided, backend);
  return decided;
}

}  // namespace exitance
