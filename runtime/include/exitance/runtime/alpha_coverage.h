// glTF alphaMode for rays: which hits on a MASK or BLEND surface stop a ray. Every ray query of the
// CPU backend (paths, shadow rays, probes) applies it through Embree's filter functions, so a fence
// or a leaf casts the shadow of its opaque texels, not of its quad.
#pragma once
#include <cstdint>

#include "exitance/common/surface_alpha.h"
#include "exitance/runtime/scene.h"

namespace exitance {

// Coverage at barycentrics (b1, b2) of `triangle`: base_alpha times the base colour texture's
// alpha (bilinear, with the texture's wrap modes and transform) times COLOR_0's alpha, in [0, 1].
float surface_coverage(const Scene& scene, uint32_t triangle, float b1, float b2);

// Whether the hit stops the ray. `u` is uniform in [0, 1), drawn per ray and surface (BLEND only).
bool hit_is_opaque(const Scene& scene, uint32_t triangle, float b1, float b2, float u);

// True when some material is MASK or BLEND (the scene needs the filter at all).
bool has_alpha_tested_materials(const Scene& scene);

// blend_decision_number (the u of BLEND hits): exitance/common/surface_alpha.h, shared with the kernels.

}  // namespace exitance
