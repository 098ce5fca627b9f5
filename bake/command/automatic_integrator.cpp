#include "exitance/bake/command/automatic_integrator.h"

namespace exitance {

IntegratorMode automatic_integrator(const BakeOptions& options, const Integrator& backend) {
  if (backend.backend_name() != "cpu") return IntegratorMode::Path;
  if (options.lighting.directional != DirectionalMode::Off) return IntegratorMode::Path;
  if (options.lighting.guiding != GuidingMode::Off) return IntegratorMode::Path;
  if (options.adaptive_request == AdaptiveRequest::On) return IntegratorMode::Path;
  return IntegratorMode::Bounces;
}

BakeOptions with_integrator_decided(const BakeOptions& options, const Integrator& backend) {
  BakeOptions decided = options;
  if (options.integrator_auto) decided.lighting.integrator = automatic_integrator(options, backend);
  return decided;
}

}  // namespace exitance
