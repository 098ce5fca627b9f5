// The octree an SVO-guiding test hands the integrator: the bake's for `texel_density`, at least 64
// leaves per axis, because the test atlases are coarse (2-8 texels per unit), where the bake's
// default (leaves ~4 texels wide) would leave 2-8 leaves.
#pragma once
#include <algorithm>

#include "exitance/bake/voxelize/svo_build.h"
#include "exitance/formats/sparse_voxel_octree.h"
#include "exitance/runtime/scene.h"

namespace exitance::testing {

inline formats::SparseVoxelOctree guiding_octree(const Scene& scene, float texel_density) {
  SvoBuildSettings build;
  build.depth = std::max(6u, default_svo_depth(scene, texel_density));
  return build_sparse_voxel_octree(scene, build);
}

}  // namespace exitance::testing
