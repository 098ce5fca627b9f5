// Which edits only scale a light layer (issue 32; docs/runtime.md "Light layers"): a punctual
// light's intensity or colour, a material's emissiveFactor or emissiveStrength, a constant sky's
// colour, each with nothing else changed. Their layers are scaled on the device with 0 rays
// (RefreshSession::apply_edits); any other edit takes the usual path.
#pragma once
#include <optional>
#include <vector>

#include "exitance/common/gpu_layout.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/refresh/scene_edits.h"

namespace exitance {

// The lighting scene's lights before an edit, as far as scaling reads them.
struct LightsBefore {
  std::vector<GpuPunctualLight> punctual;
  std::vector<GpuMaterial> materials;
  Vec3 sky{0, 0, 0};
  bool sky_image = false;
};

LightsBefore lights_before(const LightingScene& scene);

// Per light layer of `after` (light_layer_count of them): rgb factor and w = 1 where the edit
// scaled the layer, w = 0 where it kept it. nullopt when the edit did anything a factor per layer
// cannot express: geometry moved, a light moved, turned or changed its cone, an emission or sky
// channel went from 0 to more, the sky is or became an image, or a light shares its layer (beyond
// the layer limit) with another. No change at all gives factors whose w are all 0.
std::optional<std::vector<Vec4>> light_layer_factors(const LightsBefore& before, const LightingScene& after, const EditEffects& effects);

}  // namespace exitance
