// Sealed texels: live texels that no light can reach (under a box standing on the floor, inside
// closed single-sided geometry), found before the lighting stage so it does not trace them.
// Stricter than the checks' "enclosed" warning (a majority of back-face hits): a texel is sealed
// only when every test ray hits the back face of an opaque single-sided surface and no punctual
// light has a clear line to it. What such a texel would receive is then only light that slipped
// through a gap narrower than the rays' stratification (bench/results/dead-work.md measures it).
#pragma once
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

SealedTexels find_sealed_texels(const Scene& scene, const EmbreeScene& embree, const TexelGBuffer& gbuffer);

}  // namespace exitance
