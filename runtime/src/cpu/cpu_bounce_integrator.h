// The per-bounce mode (IntegratorMode::Bounces, issue 10) on the CPU backend: B_0 by the path
// estimator restricted to direct light, then one pass per bounce over every texel, each gathering
// the previous bounce's stored outgoing radiance at the hits of cosine rays. See the .cpp for the
// schedule and docs/lighting-core.md for the bias this cache lookup carries.
#pragma once
#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/integrator_settings.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

class EmbreeScene;

// E/pi at every live texel as the sum of the bounce layers B_0..B_K, each kept separately
// (LightmapEstimate::bounces, recorded_bounces = K + 1; they sum to the total), with
// bounce_statistics filled. Uses spp, time_budget_seconds, target_relative_error, max_bounces,
// seed, safety_bounce_cap, sampling_strategy, progress.
LightmapEstimate bake_per_bounce(const LightingScene& scene, const EmbreeScene& embree, const TexelGBuffer& gbuffer,
                                 const IntegratorSettings& settings);

}  // namespace exitance
