// radiance.vdb: the SVO's leaves as OpenVDB grids, for inspection in DCC tools (Houdini, Blender).
#pragma once
#include <string>

#include "exitance/formats/sparse_voxel_octree.h"

namespace exitance {

// Writes grids at leaf resolution, one active voxel per occupied leaf:
//   "occupancy"       FloatGrid (fog volume), 1 in occupied leaves, background 0
//   "exitance_front"  Vec3SGrid, radiant exitance M = pi * L_o (RGB, W/m^2 in scene units) on the
//   "exitance_back"   Vec3SGrid  side the voxel normal points to / the opposite side
//   "normal"          Vec3SGrid, the leaf's unit (front-side) normal
// Index (i, j, k) is the leaf whose centre is origin + (i + 0.5, j + 0.5, k + 0.5) * leaf_size,
// i.e. i, j, k are the leaf's integer cell coordinates in the octree's cube. Each grid carries the
// metadata "units" and "definition". Throws std::runtime_error naming `path` when OpenVDB fails.
void write_radiance_vdb(const std::string& path, const formats::SparseVoxelOctree& svo);

}  // namespace exitance
