// Refitting the BVH4 after geometry moved (runtime scene edits, refresh/scene_edits.h): the tree's
// topology and leaf slots stay as the offline stage built them, only the child boxes are
// recomputed bottom-up from the triangles' current vertices. Exact: each leaf box is the float
// min/max of its triangles' vertices and each inner box the min/max of its children's, so every
// triangle lies inside every box above it (traversal stays correct); the tree's quality degrades
// as instances move far from where it was built, which only costs speed.
#pragma once
#include <vector>

#include "exitance/runtime/core/bvh4.h"
#include "exitance/runtime/vec_math.h"

namespace exitance {

// `positions`: 3 vertices per triangle (Scene::positions). Throws std::invalid_argument when a leaf
// slot names a triangle `positions` does not have or a child word names a node that does not come
// after its parent (the depth-first layout every builder here writes); `bvh` is unchanged then.
void refit_bvh4(Bvh4& bvh, const std::vector<Vec3>& positions);

}  // namespace exitance
