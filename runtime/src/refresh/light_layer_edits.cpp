#include "exitance/runtime/refresh/light_layer_edits.h"

#include <cstring>

#include "exitance/common/light_layers.h"

namespace exitance {
namespace {

// after = factor * before per channel; a channel at 0 before stays 0 (its factor is 1).
std::optional<Vec3> channel_factors(Vec3 before, Vec3 after) {
  Vec3 f{1, 1, 1};
  for (int c = 0; c < 3; ++c) {
    if (before[c] > 0) f[c] = after[c] / before[c];
    else if (after[c] != before[c]) return std::nullopt;
  }
  return f;
}

Vec3 xyz(const Vec4& v) { return {v.x, v.y, v.z}; }
bool is_zero(Vec3 v) { return v.x == 0 && v.y == 0 && v.z == 0; }

bool same_bits(const Vec4& a, const Vec4& b) { return std::memcmp(&a, &b, sizeof(Vec4)) == 0; }

// Sets layer `layer`'s factor; false when it already has another (two lights share it).
bool set_factor(std::vector<Vec4>& factors, uint32_t layer, Vec3 f) {
  if (layer >= factors.size()) return false;
  Vec4& slot = factors[layer];
  if (slot.w != 0 && (slot.x != f[0] || slot.y != f[1] || slot.z != f[2])) return false;
  slot = Vec4(f, 1.0f);
  return true;
}

}  // namespace

LightsBefore lights_before(const LightingScene& scene) {
  return {scene.punctual_lights, scene.materials, scene.sky, scene.environment.enabled()};
}

std::optional<std::vector<Vec4>> light_layer_factors(const LightsBefore& before, const LightingScene& after, const EditEffects& effects) {
  if (effects.geometry_changed()) return std::nullopt;
  std::vector<Vec4> factors(after.light_layer_count, Vec4(1.0f, 1.0f, 1.0f, 0.0f));
  const uint32_t punctual = after.punctual_count();
  if (before.punctual.size() != punctual || before.materials.size() != after.materials.size()) return std::nullopt;
  for (uint32_t i : effects.lights) {
    if (i >= punctual) return std::nullopt;
    const GpuPunctualLight& b = before.punctual[i];
    const GpuPunctualLight& a = after.punctual_lights[i];
    if (!same_bits(a.position_type, b.position_type) || !same_bits(a.direction_cos_inner, b.direction_cos_inner) ||
        a.intensity_cos_outer.w != b.intensity_cos_outer.w)
      return std::nullopt;
    const std::optional<Vec3> f = channel_factors(xyz(b.intensity_cos_outer), xyz(a.intensity_cos_outer));
    if (!f) return std::nullopt;
    // Lights beyond the limit share the last punctual layer: scaled only if it is theirs alone.
    const uint32_t layer = punctual_light_layer(i, after.punctual_light_layers);
    if (punctual > after.punctual_light_layers && layer == after.punctual_light_layers) return std::nullopt;
    if (!set_factor(factors, layer, *f)) return std::nullopt;
  }
  for (uint32_t m : effects.materials) {
    if (m >= after.materials.size()) return std::nullopt;
    const GpuMaterial& b = before.materials[m];
    const GpuMaterial& a = after.materials[m];
    if (!same_bits(a.albedo_double_sided, b.albedo_double_sided)) return std::nullopt;
    const std::optional<Vec3> f = channel_factors(xyz(b.emission), xyz(a.emission));
    if (!f) return std::nullopt;
    if (is_zero(xyz(b.emission))) continue;  // not an emitter before or after: no light changed
    // A layer several emissive materials share (beyond the limit) is scaled only if it is this one's alone.
    const uint32_t layer = after.material_light_layers[m];
    for (size_t k = 0; k < after.materials.size(); ++k)
      if (k != m && after.material_light_layers[k] == layer && !is_zero(xyz(before.materials[k].emission))) return std::nullopt;
    if (!set_factor(factors, layer, *f)) return std::nullopt;
  }
  if (effects.sky) {
    if (before.sky_image || after.environment.enabled()) return std::nullopt;
    const std::optional<Vec3> f = channel_factors(before.sky, after.sky);
    if (!f || !set_factor(factors, kSkyLightLayer, *f)) return std::nullopt;
  }
  return factors;
}

}  // namespace exitance
