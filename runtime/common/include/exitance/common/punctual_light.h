// KHR_lights_punctual falloff.
#ifndef EXITANCE_COMMON_PUNCTUAL_LIGHT_H
#define EXITANCE_COMMON_PUNCTUAL_LIGHT_H
#include "exitance/common/dialect.h"
EXITANCE_NAMESPACE_BEGIN

const uint kPunctualPoint = 0u;
const uint kPunctualSpot = 1u;
const uint kPunctualDirectional = 2u;

// Spot falloff of the KHR_lights_punctual reference implementation (squared linear ramp in cos).
// `direction`: where the spot points; `light_to_point`: unit vector from the light to the point.
EXITANCE_FN float spot_attenuation(vec3 direction, float cos_inner, float cos_outer, vec3 light_to_point) {
  float cd = dot(direction, light_to_point);
  float scale = 1.0f / max(0.001f, cos_inner - cos_outer);
  float t = clamp((cd - cos_outer) * scale, 0.0f, 1.0f);
  return t * t;
}

EXITANCE_NAMESPACE_END
#endif
