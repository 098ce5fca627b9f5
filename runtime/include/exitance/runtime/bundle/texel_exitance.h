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

// Where fill_svo_exitance deposits each texel, for a device that computes the same from a published
// estimate every frame (vulkan/voxel_exitance_publishing.h): the texels of each leaf side in G-buffer
// order (side s = 2 node + (0 front, 1 back)), each with its weight (surface area), emitted radiance
// and albedo (M = pi (emitted + albedo E/pi)); per node whether its front faces away from its
// parent's (the filters' flip). Texels outside every leaf are left out, as the deposit drops them.
struct VoxelDeposits {
  std::vector<uint32_t> side_first;  // 2 nodes + 1: side s's entries are [side_first[s], side_first[s + 1])
  std::vector<uint32_t> texel;       // per entry
  std::vector<float> weight;
  std::vector<Vec3> emitted, albedo;
  std::vector<uint8_t> flipped;      // per node (the root: 0)
};
VoxelDeposits voxel_deposits(const formats::SparseVoxelOctree& svo, const Scene& scene, const TexelGBuffer& gbuffer);

}  // namespace exitance
