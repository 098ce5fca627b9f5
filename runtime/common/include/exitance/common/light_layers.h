// Light layers (issue 32, docs/runtime.md "Light layers"): the runtime's estimate of E/pi per texel
// kept as a sum of layers, one per source of light, so that an edit that only scales a light's
// emission scales its layer (0 rays, exact) and the others keep their samples. Every contribution
// of a path comes from one light: the one its next-event sample chose, or the emitter (or sky) its
// continuation met; MIS weights are today's, so the layers sum to the estimator.
// Layer order: 0 the sky; then one per punctual light (lights beyond the limit share the last of
// them); then one per material emissive when the scene was laid out (the same for materials); last,
// one for materials that became emissive later (an edit), shared.
#ifndef EXITANCE_COMMON_LIGHT_LAYERS_H
#define EXITANCE_COMMON_LIGHT_LAYERS_H
#include "exitance/common/dialect.h"
EXITANCE_NAMESPACE_BEGIN

const uint kSkyLightLayer = 0u;
// Default limit of layers per kind (punctual lights, emissive materials): 64 each.
const uint kDefaultLightLayerLimit = 64u;

// How many layers `lights` punctual lights get with at most `limit` per kind.
EXITANCE_FN uint punctual_light_layer_count(uint lights, uint limit) { return min(lights, limit); }

// The layer of punctual light `light` with `punctual_layers` layers for punctual lights.
EXITANCE_FN uint punctual_light_layer(uint light, uint punctual_layers) {
  return 1u + min(light, punctual_layers - 1u);
}

EXITANCE_NAMESPACE_END
#endif
