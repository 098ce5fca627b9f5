#include "exitance/runtime/material_eval.h"

#include <cmath>

#include "exitance/common/material.h"
#include "exitance/runtime/alpha_coverage.h"

namespace exitance {
namespace {

int wrap_index(int i, int n, Texture::Wrap wrap) {
  switch (wrap) {
    case Texture::Wrap::ClampToEdge: return std::clamp(i, 0, n - 1);
    case Texture::Wrap::MirroredRepeat: {
      const int period = 2 * n;
      int m = ((i % period) + period) % period;
      return m < n ? m : period - 1 - m;
    }
    default: return ((i % n) + n) % n;
  }
}

Vec3 texel(const Texture& t, int x, int y) {
  const size_t i = (size_t(y) * size_t(t.width) + size_t(x)) * 3;
  return {t.rgb[i], t.rgb[i + 1], t.rgb[i + 2]};
}

Vec2 interpolate(const std::vector<Vec2>& values, uint32_t triangle, float b1, float b2) {
  const size_t base = size_t(triangle) * 3;
  return values[base] * (1.0f - b1 - b2) + values[base + 1] * b1 + values[base + 2] * b2;
}

Vec3 lookup(const Scene& scene, const TextureBinding& binding, uint32_t triangle, float b1, float b2) {
  if (binding.texture < 0) return {1, 1, 1};
  return sample_texture(scene.textures[size_t(binding.texture)], binding_uv(scene, binding, triangle, b1, b2));
}

// Bilinear filtering of fetch(x, y) over the texture's texels with its wrap modes.
template <typename Fetch>
auto bilinear(const Texture& texture, Vec2 uv, const Fetch& fetch) {
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return fetch(0, 0);
  // Keep the coordinate small before flooring so huge UVs cannot overflow int.
  const float x = float(std::fmod(double(uv.x), 2.0 * 65536.0)) * float(texture.width) - 0.5f;
  const float y = float(std::fmod(double(uv.y), 2.0 * 65536.0)) * float(texture.height) - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float tx = x - fx, ty = y - fy;
  const int x0 = int(fx), y0 = int(fy);
  const int xa = wrap_index(x0, texture.width, texture.wrap_s), xb = wrap_index(x0 + 1, texture.width, texture.wrap_s);
  const int ya = wrap_index(y0, texture.height, texture.wrap_t), yb = wrap_index(y0 + 1, texture.height, texture.wrap_t);
  return (fetch(xa, ya) * (1 - tx) + fetch(xb, ya) * tx) * (1 - ty) + (fetch(xa, yb) * (1 - tx) + fetch(xb, yb) * tx) * ty;
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
  if (t.rotation == 0.0f && t.scale.x == 1.0f && t.scale.y == 1.0f && t.offset.x == 0.0f && t.offset.y == 0.0f)
    return uv;
  const float c = std::cos(t.rotation), s = std::sin(t.rotation);
  const Vec2 scaled{uv.x * t.scale.x, uv.y * t.scale.y};
  // KHR_texture_transform's rotation matrix: [c s; -s c] applied to (u, v).
  return {c * scaled.x + s * scaled.y + t.offset.x, -s * scaled.x + c * scaled.y + t.offset.y};
}

Vec3 diffuse_albedo(const Scene& scene, uint32_t triangle, float b1, float b2) {
  const Material& m = scene.materials[scene.triangle_material[triangle]];
  return diffuse_albedo_of(m.base_color * lookup(scene, m.base_color_texture, triangle, b1, b2), m.metallic);
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
