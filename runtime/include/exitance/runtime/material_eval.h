// Evaluates a triangle's material at a surface point: diffuse albedo and emitted radiance.
#pragma once
#include "exitance/runtime/scene.h"

namespace exitance {

// Bilinear lookup with the texture's wrap modes; uv in glTF convention ((0,0) = top-left).
Vec3 sample_texture(const Texture& texture, Vec2 uv);
// The same lookup of the texture's alpha (1 when it has none).
float sample_texture_alpha(const Texture& texture, Vec2 uv);

// The texture coordinate a binding reads at barycentrics (b1, b2) of `triangle` (its UV set, then
// its KHR_texture_transform).
Vec2 binding_uv(const Scene& scene, const TextureBinding& binding, uint32_t triangle, float b1, float b2);

// Applies KHR_texture_transform to a texture coordinate.
Vec2 apply_texture_transform(const TextureTransform& transform, Vec2 uv);

// Barycentrics (b1, b2) weight vertices 1 and 2 of the triangle.
Vec3 diffuse_albedo(const Scene& scene, uint32_t triangle, float b1, float b2);
// Zero where a MASK material's coverage is below its cutoff: rays pass there, so light sampling
// must not find emission there either.
Vec3 emitted_radiance(const Scene& scene, uint32_t triangle, float b1, float b2);

// True when the material of `triangle` emits anything (factor > 0).
bool is_emissive(const Scene& scene, uint32_t triangle);

// Mean of a texture's texels: an emitter's average radiance for power-proportional light selection.
Vec3 texture_mean(const Texture& texture);

}  // namespace exitance
