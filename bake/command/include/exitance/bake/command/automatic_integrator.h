// `bake --integrator auto` (the default): which lighting integrator a bake runs once its backend is
// chosen. The per-bounce mode reached 1 % relMSE first on 4 of the 5 sample scenes on the CPU
// backend (bench/results/per-bounce-traced.md: 0.18-0.5x the path tracer's time, its resolution
// bias measured at relMSE 2e-6..2.5e-3), so it is the default where it exists and nothing in the
// bake needs path tracing; elsewhere the unbiased path tracer.
#pragma once
#include "exitance/bake/bake_options.h"
#include "exitance/runtime/core/integrator.h"

namespace exitance {

// Path tracing on the Vulkan backend (measured on an H200, bench/results/per-bounce-gpu.md: path
// tracing reaches a given relMSE 1-9x sooner there, its per-bounce passes being bound by the host's
// cache builds between layers) and for what only it
// estimates: --directional sh1, --guiding grid, --adaptive on; else the per-bounce mode.
// (--guiding auto does not ask for path tracing: it guides path tracing when that runs.)
IntegratorMode automatic_integrator(const BakeOptions& options, const Integrator& backend);

// `--guiding auto` once the backend and integrator are known: Auto (the measured per-region choice,
// core/guiding_choice.h) when the CPU backend path traces in one process, or the Vulkan backend does
// and --guiding auto was given (options.guiding_auto_given: by default GPU bakes pay no pilot, a
// guided GPU bake costing 22-38x the time per spp today, bench/results/guiding-gpu.md); Off
// elsewhere: per-bounce passes are not guided, guiding is not split over ranks. Other modes pass through.
GuidingMode automatic_guiding(const BakeOptions& options, const Integrator& backend);

// `--emitter-guiding auto`: on where the CPU backend bakes in one process, path tracing or per-bounce
// (the only places it is implemented; records that gain little sample by default:
// core/emitter_guiding_cache.h), off elsewhere.
bool automatic_emitter_guiding(const BakeOptions& options, const Integrator& backend);

// `options` with lighting.integrator decided by automatic_integrator when options.integrator_auto,
// lighting.guiding by automatic_guiding, and lighting.emitter_guiding by automatic_emitter_guiding
// when options.emitter_guiding_auto.
BakeOptions with_integrator_decided(const BakeOptions& options, const Integrator& backend);

}  // namespace exitance
