#include "exitance/runtime/refresh/bundle_light_layers.h"

#include "exitance/common/light_layers.h"

namespace exitance {

std::optional<BundleLightLayers> bundle_light_layers(const LightingScene& session) {
  // The layout the written scene gets when a session opens it: only the lights and materials count.
  LightingScene fresh;
  fresh.materials = session.materials;
  fresh.punctual_lights = session.punctual_lights;
  lay_out_light_layers(fresh, kDefaultLightLayerLimit);
  constexpr uint32_t kUnset = ~0u;
  std::vector<uint32_t> map(session.light_layer_count, kUnset);
  bool consistent = true;
  auto assign = [&](uint32_t from, uint32_t to) {
    if (from >= map.size()) {
      consistent = false;
    } else if (map[from] == kUnset) {
      map[from] = to;
    } else if (map[from] != to) {
      consistent = false;
    }
  };
  assign(kSkyLightLayer, kSkyLightLayer);
  for (uint32_t i = 0; i < session.punctual_count(); ++i)
    assign(punctual_light_layer(i, session.punctual_light_layers), punctual_light_layer(i, fresh.punctual_light_layers));
  for (size_t m = 0; m < session.materials.size() && m < session.material_light_layers.size(); ++m) {
    const auto& e = session.materials[m].emission;
    if (e.x > 0 || e.y > 0 || e.z > 0) assign(session.material_light_layers[m], fresh.material_light_layers[m]);
  }
  if (!consistent) return std::nullopt;
  // A layer with no light now (a material turned off, the shared "later" layer unused) adds into the
  // bundle's "later" layer, which holds the materials without emission.
  const uint32_t later = fresh.light_layer_count - 1;
  for (uint32_t& to : map)
    if (to == kUnset) to = later;
  return BundleLightLayers{std::move(map), fresh.light_layer_count, fresh.punctual_light_layers};
}

}  // namespace exitance
