#include "gpu_surfaces.h"

#include <stdexcept>

#include "exitance/runtime/alpha_coverage.h"

namespace exitance::vulkan {
namespace {

static_assert(sizeof(GpuMaterialSurface) == kMaterialSurfaceWords * 16 && sizeof(GpuTexture) == 16);

uint32_t texture_index(const TextureBinding& binding) {
  return binding.texture >= 0 ? uint32_t(binding.texture) : kNoTexture;
}

GpuMaterialSurface material_surface(const Material& m) {
  GpuMaterialSurface g;
  const TextureTransform& base = m.base_color_texture.transform;
  const TextureTransform& emissive = m.emissive_texture.transform;
  g.base_color_metallic = Vec4(m.base_color, m.metallic);
  g.base_offset_scale = Vec4(base.offset.x, base.offset.y, base.scale.x, base.scale.y);
  g.emissive_offset_scale = Vec4(emissive.offset.x, emissive.offset.y, emissive.scale.x, emissive.scale.y);
  g.rotations_alpha = Vec4(base.rotation, emissive.rotation, m.alpha_cutoff, m.base_alpha);
  const uint32_t tex_coords = uint32_t(base.tex_coord == 1 ? 1 : 0) | uint32_t(emissive.tex_coord == 1 ? 1 : 0) << 8;
  g.textures_mode = Vec4(uintBitsToFloat(texture_index(m.base_color_texture)), uintBitsToFloat(texture_index(m.emissive_texture)),
                         uintBitsToFloat(tex_coords), uintBitsToFloat(uint32_t(m.alpha_mode)));
  return g;
}

Vec4 uint_word(uint32_t x, uint32_t y, uint32_t z, uint32_t w) {
  return Vec4(uintBitsToFloat(x), uintBitsToFloat(y), uintBitsToFloat(z), uintBitsToFloat(w));
}

}  // namespace

uint32_t surface_flags(const LightingScene& lighting) {
  if (!lighting.textured) return 0;
  const Scene& scene = *lighting.source;
  uint32_t flags = kSurfaceTextured;
  if (!scene.vertex_color.empty()) flags |= kSurfaceVertexColor;
  if (!scene.vertex_alpha.empty()) flags |= kSurfaceVertexAlpha;
  if (has_alpha_tested_materials(scene)) flags |= kSurfaceAlphaMaterials;
  return flags;
}

std::vector<Vec4> material_surface_words(const Scene& scene, const SurfaceLayout& layout) {
  std::vector<Vec4> words{uint_word(layout.textures, layout.corner_uvs, layout.corner_colors, layout.texels)};
  for (const Material& m : scene.materials) {
    const GpuMaterialSurface g = material_surface(m);
    words.insert(words.end(), {g.base_color_metallic, g.base_offset_scale, g.emissive_offset_scale, g.rotations_alpha, g.textures_mode});
  }
  return words;
}

std::vector<Vec4> surface_words(const LightingScene& lighting, SurfaceLayout& layout) {
  const Scene& scene = *lighting.source;
  const size_t material_end = kSurfaceHeaderWords + scene.materials.size() * kMaterialSurfaceWords;
  layout = {uint32_t(material_end), uint32_t(material_end), uint32_t(material_end), uint32_t(material_end)};
  if (!lighting.textured) return material_surface_words(scene, layout);

  const size_t corners = scene.triangle_count() * 3;
  size_t texel_count = 0;
  for (const Texture& t : scene.textures) texel_count += size_t(t.width) * size_t(t.height);
  const size_t textures = material_end, corner_uvs = textures + scene.textures.size(), corner_colors = corner_uvs + corners;
  const size_t texels = corner_colors + (scene.vertex_color.empty() ? 0 : corners), total = texels + texel_count;
  if (total > size_t(UINT32_MAX) / 16)
    throw std::runtime_error("Vulkan backend: the scene's textures and corners need more than 4 GiB of surface data");
  layout = {uint32_t(textures), uint32_t(corner_uvs), uint32_t(corner_colors), uint32_t(texels)};

  std::vector<Vec4> words = material_surface_words(scene, layout);
  words.reserve(total);
  size_t offset = 0;
  for (const Texture& t : scene.textures) {
    const uint32_t wrap = uint32_t(t.wrap_s) | uint32_t(t.wrap_t) << 8 | (t.alpha.empty() ? 0u : kTextureHasAlpha);
    words.push_back(uint_word(uint32_t(offset), uint32_t(t.width), uint32_t(t.height), wrap));
    offset += size_t(t.width) * size_t(t.height);
  }
  for (size_t c = 0; c < corners; ++c) {
    const Vec2 uv0 = c < scene.uv0.size() ? scene.uv0[c] : Vec2{};
    const Vec2 uv1 = c < scene.lightmap_uv.size() ? scene.lightmap_uv[c] : Vec2{};
    words.emplace_back(uv0.x, uv0.y, uv1.x, uv1.y);
  }
  if (!scene.vertex_color.empty())
    for (size_t c = 0; c < corners; ++c)
      words.emplace_back(scene.vertex_color[c], scene.vertex_alpha.empty() ? 1.0f : scene.vertex_alpha[c]);
  for (const Texture& t : scene.textures)
    for (size_t i = 0, n = size_t(t.width) * size_t(t.height); i < n; ++i)
      words.emplace_back(t.rgb[i * 3], t.rgb[i * 3 + 1], t.rgb[i * 3 + 2], t.alpha.empty() ? 1.0f : t.alpha[i]);
  return words;
}

}  // namespace exitance::vulkan
