#include "exitance/runtime/material_eval.h"

#include <cmath>

#include "exitance/common/material.h"
#include "exitance/common/texture_sampling.h"
#include "exitance/runtime/alpha_coverage.h"

namespace exitance {
namespace {

Vec3 texel(const Texture& t, int x, int y) {
  const size_t i = (size_t(y) * size_t(t.width) + size_t(x)) * 3;
  return {t.rgb[i], t.rgb[i + 1], t.rgb[i + 2]};
}

template <class T>
T interpolate(const std::vector<T>& values, uint32_t triangle, float b1, float b2) {
  const size_t base = size_t(triangle) * 3;
  return values[base] * (1.0f - b1 - b2) + values[base + 1] * b1 + values[base + 2] * b2;
}

Vec3 lookup(const Scene& scene, const TextureBinding& binding, uint32_t triangle, float b1, float b2) {
  if (binding.texture < 0) return {1, 1, 1};
  return sample_texture(scene.textures[size_t(binding.texture)], binding_uv(scene, binding, triangle, b1, b2));
}

// Bilinear filtering of fetch(x, y) over the texture's texels with its wrap modes (the footprint
// and weights are texture_sampling.h's, shared with the kernels).
template <typename Fetch>
auto bilinear(const Texture& texture, Vec2 uv, const Fetch& fetch) {
  const BilinearTaps taps = bilinear_taps(uv, texture.width, texture.height, uint32_t(texture.wrap_s), uint32_t(texture.wrap_t));
  return bilinear_mix(fetch(taps.x0, taps.y0), fetch(taps.x1, taps.y0), fetch(taps.x0, taps.y1), fetch(taps.x1, taps.y1), taps);
}

}  // namespace

Vec2 binding_uv(const Scene& scene, const TextureBinding& binding, uint32_t triangle, float b1, float b2) {
  const std::vector<Vec2>& set = binding.transform.tex_coord == 1 ? scene.lightmap_uv : scene.uv0;
  return apply_texture_transform(binding.transform, interpolate(set, triangle, b1, b2));
}

Vec3 sample_texture(const Texture& texture, Vec2 uv) {
  return bilinear(texture, uv, [&](int x, int y) { return texel(texture, x, y); });
}

float sample_texture_alpha(const Texture& texture, Vec2 uv) {
  if (texture.alpha.empty()) return 1.0f;
  return bilinear(texture, uv, [&](int x, int y) { return texture.alpha[size_t(y) * size_t(texture.width) + size_t(x)]; });
}

Vec2 apply_texture_transform(const TextureTransform& t, Vec2 uv) {
  return transform_texture_coordinate(uv, t.offset, t.scale, t.rotation);
}

Vec3 diffuse_albedo(const Scene& scene, uint32_t triangle, float b1, float b2) {
  const Material& m = scene.materials[scene.triangle_material[triangle]];
  Vec3 base = m.base_color * lookup(scene, m.base_color_texture, triangle, b1, b2);
  if (!scene.vertex_color.empty()) base = base * interpolate(scene.vertex_color, triangle, b1, b2);
  return diffuse_albedo_of(base, m.metallic);
}

Vec3 emitted_radiance(const Scene& scene, uint32_t triangle, float b1, float b2) {
  const Material& m = scene.materials[scene.triangle_material[triangle]];
  if (max_component(m.emission) <= 0.0f) return {0, 0, 0};
  if (m.alpha_mode == Material::AlphaMode::Mask && surface_coverage(scene, triangle, b1, b2) < m.alpha_cutoff)
    return {0, 0, 0};
  return m.emission * lookup(scene, m.emissive_texture, triangle, b1, b2);
}

bool is_emissive(const Scene& scene, uint32_t triangle) {
  return max_component(scene.materials[scene.triangle_material[triangle]].emission) > 0.0f;
}

Vec3 texture_mean(const Texture& texture) {
  double r = 0, g = 0, b = 0;
  for (size_t i = 0; i + 2 < texture.rgb.size(); i += 3) r += texture.rgb[i], g += texture.rgb[i + 1], b += texture.rgb[i + 2];
  const double n = std::max<double>(1.0, double(texture.rgb.size() / 3));
  return {float(r / n), float(g / n), float(b / n)};
}

}  // namespace exitance
