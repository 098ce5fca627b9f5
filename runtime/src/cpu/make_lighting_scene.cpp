#include "exitance/runtime/cpu/bvh4_builder.h"
#include "exitance/runtime/cpu_reference_integrator.h"

namespace exitance {

std::shared_ptr<const LightingScene> make_lighting_scene(const Scene& scene) {
  auto source = std::make_shared<const Scene>(scene);
  Bvh4 bvh = build_bvh4(*source);
  return std::make_shared<const LightingScene>(build_lighting_scene(std::move(source), std::move(bvh)));
}

}  // namespace exitance
