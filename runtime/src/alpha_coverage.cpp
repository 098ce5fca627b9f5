#include "exitance/runtime/alpha_coverage.h"

#include <algorithm>
#include <cmath>

#include "exitance/runtime/material_eval.h"

namespace exitance {

float surface_coverage(const Scene& scene, uint32_t triangle, float b1, float b2) {
  const Material& m = scene.materials[scene.triangle_material[triangle]];
  float coverage = m.base_alpha;
  if (m.base_color_texture.texture >= 0) {
    const Texture& texture = scene.textures[size_t(m.base_color_texture.texture)];
    coverage *= sample_texture_alpha(texture, binding_uv(scene, m.base_color_texture, triangle, b1, b2));
  }
  if (!scene.vertex_alpha.empty()) {
    const float* a = &scene.vertex_alpha[size_t(triangle) * 3];
    coverage *= a[0] * (1 - b1 - b2) + a[1] * b1 + a[2] * b2;
  }
  return clamped_coverage(coverage);
}

bool hit_is_opaque(const Scene& scene, uint32_t triangle, float b1, float b2, float u) {
  const Material& m = scene.materials[scene.triangle_material[triangle]];
  if (m.alpha_mode == Material::AlphaMode::Opaque) return true;
  return coverage_stops_ray(uint32_t(m.alpha_mode), surface_coverage(scene, triangle, b1, b2), m.alpha_cutoff, u);
}

bool has_alpha_tested_materials(const Scene& scene) {
  return std::any_of(scene.materials.begin(), scene.materials.end(),
                     [](const Material& m) { return m.alpha_mode != Material::AlphaMode::Opaque; });
}

}  // namespace exitance
