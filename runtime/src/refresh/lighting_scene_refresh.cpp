// update_lighting_scene (scene_edits.h): the LightingScene after edits, by the cheapest of
// lighting_scene.h's in-place updates that covers what changed.
#include <stdexcept>

#include "exitance/runtime/refresh/scene_edits.h"

namespace exitance {

void update_lighting_scene(LightingScene& lighting, std::shared_ptr<const Scene> edited, const EditEffects& effects) {
  if (!edited || edited->triangle_count() != lighting.triangles.size() ||
      edited->materials.size() != lighting.materials.size() || edited->lights.size() != lighting.punctual_lights.size())
    throw std::invalid_argument("update_lighting_scene: the edited scene's triangles, materials or lights differ");
  if (effects.geometry_changed()) {
    set_geometry(lighting, std::move(edited));  // all or nothing itself
    return;
  }
  LightingScene next = lighting;
  for (uint32_t m : effects.materials) set_material(next, m, edited->materials.at(m));
  for (uint32_t l : effects.lights) set_punctual_light(next, l, edited->lights.at(l));
  if (effects.sky) {
    next.sky = edited->sky.constant;
    next.environment = edited->sky.has_environment() ? EnvironmentSampler(edited->sky.environment) : EnvironmentSampler{};
  }
  next.source = std::move(edited);  // what set_material / set_punctual_light copied, plus the sky
  lighting = std::move(next);
}

}  // namespace exitance
