// Exitance of the octree node containing a point, on the side facing a normal.
#pragma once
#include "exitance/formats/sparse_voxel_octree.h"
#include "exitance/loader/lookup_results.h"

namespace exitance::loader {

// Descends with formats::svo_find_node to `max_level` or the deepest existing node above it, then
// takes the front side when dot(normal, node normal) >= 0, else the back side. The octree must be
// validated (formats::validate_octree); point and normal finite (a zero normal picks the front).
SvoExitanceResult lookup_svo_exitance(const formats::SparseVoxelOctree& svo, Point3 point, uint32_t max_level,
                                      Point3 normal);

}  // namespace exitance::loader
