// The lightmap's light as radiant exitance in the sparse voxel octree (svo.bin): what the bake and
// the runtime's relight both publish after a lightmap pass.
#pragma once
#include "exitance/formats/sparse_voxel_octree.h"
#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

// Radiant exitance M = pi * L_o = pi * (Le + albedo * E/pi) of every lit texel, deposited into the
// octree's leaves with the texel's surface area as weight (texels sample surfaces uniformly by
// area, so each leaf side gets the area-average exitance of the surface inside it), then published
// by replacement (no sums kept from an earlier bake) and filtered through the hierarchy.
void fill_svo_exitance(formats::SparseVoxelOctree& svo, const Scene& scene, const TexelGBuffer& gbuffer,
                       const LightmapEstimate& estimate);

}  // namespace exitance
