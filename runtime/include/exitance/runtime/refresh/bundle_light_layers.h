// Which of a bundle's light layers each of a session's layers is written to (docs/bundle.md "Light
// layers"). A bundle's layers follow the layout its scene.bin gets when opened
// (lay_out_light_layers); a session keeps the layout it opened with through every edit, so after an
// edit made a material emissive (its light is in the shared "later" layer) or turned one off, the
// two differ, and a session layer is written to the bundle layer its lights have there.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "exitance/runtime/core/lighting_scene.h"

namespace exitance {

struct BundleLightLayers {
  std::vector<uint32_t> bundle_layer;  // per session layer, the bundle layer it adds into
  uint32_t count = 0;                  // the bundle's layers (lay_out_light_layers of the scene now)
  uint32_t punctual = 0;               // of them, punctual lights' layers
};

// nullopt when some session layer holds lights that the bundle's layout puts in different layers
// (more than the limit of lights of a kind, shared differently): no layers are written then.
// Materials without emission now are left out of that test (their light is 0 in the scene now).
std::optional<BundleLightLayers> bundle_light_layers(const LightingScene& session);

}  // namespace exitance
