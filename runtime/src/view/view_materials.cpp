#include "exitance/runtime/view/view_materials.h"

#include "exitance/common/environment_map.h"
#include "exitance/common/material.h"
#include "exitance/common/surface_alpha.h"
#include "exitance/common/texture_sampling.h"
#include "exitance/runtime/tangent_frames.h"

namespace exitance::view {
namespace {

Vec3 to_vec3(const formats::Float3& f) { return {f[0], f[1], f[2]}; }

// Barycentric interpolation of a per-corner attribute of triangle t.
template <class T>
auto corner_mix(const std::vector<T>& values, uint32_t t, float b1, float b2) {
  const size_t c = size_t(t) * 3;
  return values[c] * (1.0f - b1 - b2) + values[c + 1] * b1 + values[c + 2] * b2;
}

Vec2 corner_uv(const std::vector<formats::Float2>& uvs, uint32_t t, float b1, float b2) {
  const size_t c = size_t(t) * 3;
  const float b0 = 1.0f - b1 - b2;
  return {uvs[c][0] * b0 + uvs[c + 1][0] * b1 + uvs[c + 2][0] * b2, uvs[c][1] * b0 + uvs[c + 1][1] * b1 + uvs[c + 2][1] * b2};
}

Vec2 binding_uv(const formats::SceneFile& scene, const formats::TextureBindingRecord& binding, uint32_t t, float b1, float b2) {
  const Vec2 uv = corner_uv(binding.tex_coord == 1 ? scene.triangles.lightmap_uv : scene.triangles.uv0, t, b1, b2);
  return transform_texture_coordinate(uv, {binding.offset[0], binding.offset[1]}, {binding.scale[0], binding.scale[1]},
                                      binding.rotation);
}

BilinearTaps taps_at(const formats::TextureRecord& texture, Vec2 uv) {
  return bilinear_taps(uv, int(texture.width), int(texture.height), uint32_t(texture.wrap_s), uint32_t(texture.wrap_t));
}

Vec3 texel_rgb(const formats::TextureRecord& texture, int x, int y) {
  const size_t i = (size_t(y) * texture.width + size_t(x)) * 3;
  return {texture.rgb[i], texture.rgb[i + 1], texture.rgb[i + 2]};
}

// A binding's filtered rgb; white without a texture.
Vec3 binding_rgb(const formats::SceneFile& scene, const formats::TextureBindingRecord& binding, uint32_t t, float b1, float b2) {
  if (binding.texture < 0) return {1, 1, 1};
  const formats::TextureRecord& texture = scene.textures[size_t(binding.texture)];
  const BilinearTaps k = taps_at(texture, binding_uv(scene, binding, t, b1, b2));
  return bilinear_mix(texel_rgb(texture, k.x0, k.y0), texel_rgb(texture, k.x1, k.y0), texel_rgb(texture, k.x0, k.y1),
                      texel_rgb(texture, k.x1, k.y1), k);
}

float binding_alpha(const formats::SceneFile& scene, const formats::TextureBindingRecord& binding, uint32_t t, float b1, float b2) {
  if (binding.texture < 0) return 1.0f;
  const formats::TextureRecord& texture = scene.textures[size_t(binding.texture)];
  if (texture.alpha.empty()) return 1.0f;
  const BilinearTaps k = taps_at(texture, binding_uv(scene, binding, t, b1, b2));
  const auto a = [&](int x, int y) { return texture.alpha[size_t(y) * texture.width + size_t(x)]; };
  return bilinear_mix(a(k.x0, k.y0), a(k.x1, k.y0), a(k.x0, k.y1), a(k.x1, k.y1), k);
}

const formats::MaterialRecord& material_of(const formats::SceneFile& scene, uint32_t t) {
  return scene.materials[scene.triangles.material[t]];
}

// base alpha x texture alpha x COLOR_0 alpha, clamped (alpha_coverage.cpp's surface_coverage).
float coverage(const formats::SceneFile& scene, uint32_t t, float b1, float b2) {
  const formats::MaterialRecord& m = material_of(scene, t);
  float c = m.base_alpha * binding_alpha(scene, m.base_color_texture, t, b1, b2);
  if (!scene.vertex_alpha.empty()) c *= corner_mix(scene.vertex_alpha, t, b1, b2);
  return clamped_coverage(c);
}

}  // namespace

Vec3 surface_albedo(const formats::SceneFile& scene, uint32_t t, float b1, float b2) {
  const formats::MaterialRecord& m = material_of(scene, t);
  Vec3 base = to_vec3(m.base_color) * binding_rgb(scene, m.base_color_texture, t, b1, b2);
  if (!scene.vertex_color.empty()) {
    const size_t c = size_t(t) * 3;
    base = base * (to_vec3(scene.vertex_color[c]) * (1.0f - b1 - b2) + to_vec3(scene.vertex_color[c + 1]) * b1 +
                   to_vec3(scene.vertex_color[c + 2]) * b2);
  }
  return diffuse_albedo_of(base, m.metallic);
}

Vec3 surface_emission(const formats::SceneFile& scene, uint32_t t, float b1, float b2) {
  const formats::MaterialRecord& m = material_of(scene, t);
  const Vec3 emission = to_vec3(m.emission);
  if (max_component(emission) <= 0.0f) return {0, 0, 0};
  if (m.alpha_mode == formats::AlphaMode::Mask && coverage(scene, t, b1, b2) < m.alpha_cutoff) return {0, 0, 0};
  return emission * binding_rgb(scene, m.emissive_texture, t, b1, b2);
}

float surface_opacity(const formats::SceneFile& scene, uint32_t t, float b1, float b2) {
  const formats::MaterialRecord& m = material_of(scene, t);
  switch (m.alpha_mode) {
    case formats::AlphaMode::Opaque: return 1.0f;
    case formats::AlphaMode::Mask: return coverage(scene, t, b1, b2) >= m.alpha_cutoff ? 1.0f : 0.0f;
    case formats::AlphaMode::Blend: return coverage(scene, t, b1, b2);
  }
  return 1.0f;
}

Vec3 surface_normal(const formats::SceneFile& scene, uint32_t t, float b1, float b2, Vec3 n) {
  const formats::MaterialRecord& m = material_of(scene, t);
  if (m.normal_texture.texture < 0 || scene.tangents.empty()) return n;
  TangentFrame frame;
  const size_t c = size_t(t) * 3;
  frame.tangent = to_vec3(scene.tangents[c]) * (1.0f - b1 - b2) + to_vec3(scene.tangents[c + 1]) * b1 +
                  to_vec3(scene.tangents[c + 2]) * b2;
  frame.sign = corner_mix(scene.tangent_signs, t, b1, b2) < 0.0f ? -1.0f : 1.0f;
  return perturbed_normal(n, frame, binding_rgb(scene, m.normal_texture, t, b1, b2), m.normal_scale);
}

Vec3 sky_radiance(const formats::SceneFile& scene, Vec3 direction) {
  const formats::TextureRecord& map = scene.sky_environment;
  if (map.width == 0 || map.height == 0) return to_vec3(scene.sky);
  const size_t i = size_t(environment_texel(direction, map.width, map.height)) * 3;
  return {map.rgb[i], map.rgb[i + 1], map.rgb[i + 2]};
}

}  // namespace exitance::view
