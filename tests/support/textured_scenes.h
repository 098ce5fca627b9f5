// Scenes whose materials vary per point (textures, KHR_texture_transform, COLOR_0, MASK, BLEND), for
// the CPU-vs-Vulkan cross-checks of lightmaps and probes.
#pragma once
#include <vector>

#include "support/test_scenes.h"

namespace exitance::testing {

// An n x n checker of colours a and b (texel (0, 0) is a), with the given wrap mode on both axes.
inline Texture checker_texture(int n, Vec3 a, Vec3 b, Texture::Wrap wrap) {
  Texture t;
  t.width = t.height = n;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const Vec3 c = (x + y) % 2 == 0 ? a : b;
      t.rgb.insert(t.rgb.end(), {c.x, c.y, c.z});
    }
  t.wrap_s = t.wrap_t = wrap;
  return t;
}

// width x 1 texture whose left half has colour `left` and alpha `left_alpha`, the right half
// `right` and `right_alpha`; clamped, so bilinear filtering blends only within a texel of u = 0.5.
inline Texture two_halves_texture(int width, Vec3 left, float left_alpha, Vec3 right, float right_alpha) {
  Texture t;
  t.width = width, t.height = 1;
  for (int x = 0; x < width; ++x) {
    const bool is_left = 2 * x < width;
    const Vec3 c = is_left ? left : right;
    t.rgb.insert(t.rgb.end(), {c.x, c.y, c.z});
    t.alpha.push_back(is_left ? left_alpha : right_alpha);
  }
  t.wrap_s = t.wrap_t = Texture::Wrap::ClampToEdge;
  return t;
}

struct TexturedScene {
  Scene scene;
  std::vector<LiveTexel> texels;  // on the floor and the back wall
  std::vector<Vec3> probes;
};

// Under a constant sky: a floor with a transformed, repeating checker albedo and COLOR_0; a back
// wall with a mirrored checker read through the lightmap UVs; a panel above emitting through a
// texture; a MASK quad with a half-covered texture and a BLEND quad whose coverage includes
// COLOR_0's alpha, both between the sky and the floor.
inline TexturedScene textured_masked_scene() {
  TexturedScene t;
  Scene& s = t.scene;
  s.sky.constant = {0.6f, 0.7f, 1.0f};
  s.textures.push_back(checker_texture(8, {0.9f, 0.6f, 0.3f}, {0.2f, 0.4f, 0.8f}, Texture::Wrap::Repeat));          // 0
  s.textures.push_back(checker_texture(4, {0.8f, 0.8f, 0.8f}, {0.1f, 0.5f, 0.1f}, Texture::Wrap::MirroredRepeat));  // 1
  s.textures.push_back(two_halves_texture(16, {1.0f, 0.2f, 0.2f}, 0.0f, {0.2f, 1.0f, 0.5f}, 1.0f));                // 2
  s.textures.push_back(checker_texture(2, {4.0f, 3.0f, 1.0f}, {0.5f, 1.0f, 3.0f}, Texture::Wrap::ClampToEdge));    // 3

  const uint32_t floor = add_material(s, {1, 1, 1});
  s.materials[floor].base_color_texture.texture = 0;
  s.materials[floor].base_color_texture.transform.scale = {1.5f, 2.0f};
  s.materials[floor].base_color_texture.transform.rotation = 0.3f;
  s.materials[floor].base_color_texture.transform.offset = {0.1f, -0.2f};
  const uint32_t wall = add_material(s, {0.9f, 0.9f, 0.9f});
  s.materials[wall].base_color_texture.texture = 1;
  s.materials[wall].base_color_texture.transform.tex_coord = 1;
  s.materials[wall].base_color_texture.transform.scale = {3.0f, 3.0f};
  const uint32_t panel = add_material(s, {0.5f, 0.5f, 0.5f}, {1.0f, 1.0f, 1.0f});
  s.materials[panel].emissive_texture.texture = 3;
  const uint32_t mask = add_material(s, {0.7f, 0.7f, 0.7f}, {0, 0, 0}, true);
  s.materials[mask].alpha_mode = Material::AlphaMode::Mask;
  s.materials[mask].base_color_texture.texture = 2;
  const uint32_t blend = add_material(s, {0.3f, 0.6f, 0.9f}, {0, 0, 0}, true);
  s.materials[blend].alpha_mode = Material::AlphaMode::Blend;
  s.materials[blend].base_alpha = 0.8f;

  add_quad(s, {-1, 0, 1}, {2, 0, 0}, {0, 0, -2}, floor);       // y = 0, facing up
  add_quad(s, {-1, 0, -1}, {2, 0, 0}, {0, 1.5f, 0}, wall);     // z = -1, facing +z
  add_quad(s, {-0.3f, 1.2f, -0.3f}, {0.6f, 0, 0}, {0, 0, 0.6f}, panel);  // facing down
  add_quad(s, {-0.9f, 0.5f, -0.5f}, {0.8f, 0, 0}, {0, 0, 1.0f}, mask);
  add_quad(s, {0.1f, 0.4f, -0.5f}, {0.8f, 0, 0}, {0, 0, 1.0f}, blend);
  // COLOR_0: a gradient over every corner (by position), alpha falling with x.
  for (const Vec3& p : s.positions) {
    s.vertex_color.push_back({0.6f + 0.2f * p.x, 0.8f, 0.7f - 0.2f * p.z});
    s.vertex_alpha.push_back(0.75f - 0.25f * p.x);
  }

  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) {
      const float x = -0.9f + 1.8f * (float(i) + 0.5f) / 8, z = -0.9f + 1.8f * (float(j) + 0.5f) / 8;
      t.texels.push_back(texel_at({x, 0, z}, {0, 1, 0}));
      t.texels.push_back(texel_at({x, 0.05f + 1.4f * (float(j) + 0.5f) / 8, -1}, {0, 0, 1}));
    }
  t.probes = {{-0.5f, 0.25f, 0.0f}, {0.5f, 0.2f, 0.0f}, {0.0f, 0.8f, 0.2f}, {0.3f, 0.1f, 0.6f}};
  return t;
}

}  // namespace exitance::testing
