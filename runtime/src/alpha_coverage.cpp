#include "exitance/runtime/alpha_coverage.h"

#include <algorithm>
#include <bit>
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
  return std::isfinite(coverage) ? std::clamp(coverage, 0.0f, 1.0f) : 1.0f;
}

bool hit_is_opaque(const Scene& scene, uint32_t triangle, float b1, float b2, float u) {
  const Material& m = scene.materials[scene.triangle_material[triangle]];
  switch (m.alpha_mode) {
    case Material::AlphaMode::Opaque: return true;
    case Material::AlphaMode::Mask: return surface_coverage(scene, triangle, b1, b2) >= m.alpha_cutoff;
    case Material::AlphaMode::Blend: return u < surface_coverage(scene, triangle, b1, b2);
  }
  return true;
}

bool has_alpha_tested_materials(const Scene& scene) {
  return std::any_of(scene.materials.begin(), scene.materials.end(),
                     [](const Material& m) { return m.alpha_mode != Material::AlphaMode::Opaque; });
}

namespace {

uint64_t mix64(uint64_t z) {  // splitmix64's finaliser: every input bit reaches every output bit
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

}  // namespace

float blend_decision_number(Vec3 origin, Vec3 direction, uint32_t triangle) {
  uint64_t h = mix64(uint64_t(triangle) + 0x9e3779b97f4a7c15ull);
  for (float f : {origin.x, origin.y, origin.z, direction.x, direction.y, direction.z})
    h = mix64(h ^ std::bit_cast<uint32_t>(f));
  return float(h >> 40) * 0x1.0p-24f;  // 24 bits: uniform in [0, 1)
}

}  // namespace exitance
