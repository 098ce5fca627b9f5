// The diffuse part of a glTF metallic-roughness material (DESIGN §4: metals reflect diffusely with
// albedo baseColor x (1 - metallic)), clamped to [0, 1] so no surface creates energy.
#ifndef EXITANCE_COMMON_MATERIAL_H
#define EXITANCE_COMMON_MATERIAL_H
#include "exitance/common/dialect.h"
EXITANCE_NAMESPACE_BEGIN

EXITANCE_FN vec3 diffuse_albedo_of(vec3 base_color, float metallic) {
  vec3 a = base_color * (1.0f - metallic);
  return vec3(clamp(a.x, 0.0f, 1.0f), clamp(a.y, 0.0f, 1.0f), clamp(a.z, 0.0f, 1.0f));
}

EXITANCE_NAMESPACE_END
#endif
