// Sealed texels: live texels that no light can reach (under a box standing on the floor, inside
// closed single-sided geometry), found before the lighting stage so it does not trace them.
// Stricter than the checks' "enclosed" warning (a majority of back-face hits): a texel is sealed
// only when every test ray hits the back face of an opaque single-sided surface and no punctual
// light has a clear line to it. What such a texel would receive is then only light that slipped
// through a gap narrower than the rays' stratification (bench/results/dead-work.md measures it).
#pragma once

#include "exitance/bake/raster/parallel_progress.h"
#include <cstddef>
#include <cstdint>
#include <vector>

#include "exitance/runtime/embree_scene.h"
#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

// Rays per texel: a first set every texel gets, and for the texels it finds closed a second,
// larger set stratified over the cosine-weighted hemisphere (a 16 x 15 grid: any opening wider
// than a grid cell in the cosine-warped square is hit for sure; see sealed_texels.cpp).
inline constexpr int kSealedFirstRays = 16;
inline constexpr int kSealedConfirmRaysU = 16;
inline constexpr int kSealedConfirmRaysV = 15;

struct SealedTexels {
  std::vector<uint8_t> sealed;  // per live texel of the G-buffer (same order): 1 = no light reaches it
  size_t texels = 0;            // sealed texels
  size_t instances = 0;         // instances with live texels, every one of them sealed
  size_t candidates = 0;        // texels whose first rays all hit single-sided back faces
};

// `closed`: per live texel, whether its first kSealedFirstRays cosine rays all ended on dead back
// faces, when already traced (the scene checks' closed_texels); null: traced here.
// `progress` (optional) hears the share of texels decided.
SealedTexels find_sealed_texels(const Scene& scene, const EmbreeScene& embree, const TexelGBuffer& gbuffer,
                                const std::vector<uint8_t>* closed = nullptr, const FractionDone& progress = {});

// A ray that ends on the back of an opaque single-sided surface brings no light: the lighting
// stage gives such hits zero radiance. A miss (the sky), a front face, a double-sided surface (its
// back is a real surface that reflects and may emit) or a surface rays can pass through (alpha
// MASK/BLEND) may bring light.
bool ends_on_dead_back_face(const Scene& scene, const Hit& hit, Vec3 direction);

}  // namespace exitance
