// The per-point surface data of a scene as the kernels read it, packed into one vec4 array
// (gpu_layout.h, kBindingSurfaces): a header, per material its factors, texture bindings and
// alphaMode, per texture its record, per triangle corner its texture coordinates and COLOR_0, and
// the texels. An untextured scene gets the header and materials only and flags 0, so its kernels
// read nothing more than before.
#pragma once
#include <cstdint>
#include <vector>

#include "exitance/common/gpu_layout.h"
#include "exitance/runtime/core/lighting_scene.h"

namespace exitance::vulkan {

// First words of each part (the header's uint bits).
struct SurfaceLayout {
  uint32_t textures = 0, corner_uvs = 0, corner_colors = 0, texels = 0;
};

// kSurface* flags of the scene: 0 unless `lighting.textured`.
uint32_t surface_flags(const LightingScene& lighting);

// Every word; textures, corners and texels only when `lighting.textured`. Texels are linear float
// rgba, 16 bytes each (the CPU reference's floats, so both backends read the same values).
std::vector<Vec4> surface_words(const LightingScene& lighting, SurfaceLayout& layout);

// The header and the material records alone (words [0, kSurfaceHeaderWords + materials x
// kMaterialSurfaceWords)), for a material edit that keeps the rest.
std::vector<Vec4> material_surface_words(const Scene& scene, const SurfaceLayout& layout);

}  // namespace exitance::vulkan
