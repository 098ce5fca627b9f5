// Materials as exitance-view draws them, over scene.bin's records (version 2): the base colour and
// emissive textures (bilinear, wrap modes, KHR_texture_transform, either UV set), COLOR_0, and
// alphaMode coverage, through the same shared math as the lighting stage
// (runtime/common/.../texture_sampling.h, surface_alpha.h, material.h), so a view shows the albedo
// the bake lit with. The image sky on a miss is looked up at its nearest texel as the bake does
// (environment_map.h).
#pragma once
#include <cstdint>

#include "exitance/formats/scene_file.h"
#include "exitance/runtime/vec_math.h"

namespace exitance::view {

// Diffuse albedo at barycentrics (b1, b2) of triangle t: base colour x texture x COLOR_0, then the
// diffuse part (metallic).
Vec3 surface_albedo(const formats::SceneFile& scene, uint32_t t, float b1, float b2);

// Emitted radiance of the front side: emission x emissive texture (0 where a MASK surface lets rays
// pass, as the bake treats it).
Vec3 surface_emission(const formats::SceneFile& scene, uint32_t t, float b1, float b2);

// How much of the surface a primary ray sees: 1 for OPAQUE; MASK 0 or 1 by alphaCutoff; BLEND the
// coverage (base alpha x texture alpha x COLOR_0 alpha), which the view composites over what lies
// behind, as an engine's alpha blending does.
float surface_opacity(const formats::SceneFile& scene, uint32_t t, float b1, float b2);

// The front side's shading normal with the material's normal map applied (tangent_frames.h,
// perturbed_normal): `n` is the interpolated normal at (b1, b2) of t, the normal texture is read
// bilinearly through its binding (linear RGB, its scale), in the frame of the corner tangents
// interpolated (handedness: the sign of the interpolated w). `n` itself where the material has no
// normal map or scene.bin stores no tangents (version 2 and older).
Vec3 surface_normal(const formats::SceneFile& scene, uint32_t t, float b1, float b2, Vec3 n);

// Sky radiance seen along unit `direction`: the image sky's nearest texel, or the constant sky.
Vec3 sky_radiance(const formats::SceneFile& scene, Vec3 direction);

}  // namespace exitance::view
