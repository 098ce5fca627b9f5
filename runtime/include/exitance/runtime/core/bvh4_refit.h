// Refitting the BVH4 after geometry moved (runtime scene edits, refresh/scene_edits.h): the tree's
// topology and leaf slots stay as the offline stage built them, only the child boxes are
// recomputed bottom-up from the triangles' current vertices, each inner box the min/max of its
// children's, so every part of a triangle a leaf refers to lies inside every box above it
// (traversal stays correct); the tree's quality degrades as instances move far from where it was
// built, which only costs speed.
//
// Leaf boxes: without the positions the boxes were fitted to, the float min/max of the leaf's
// triangles' vertices. With them, a leaf whose triangles all kept their vertices keeps its box, and
// a leaf with a moved triangle boxes each triangle's part in its old box carried to where the
// triangle went (rounded outward): the spatial-split builder's leaf boxes hold a clipped fragment
// of a triangle, tighter than the triangle's bounds, and an edit that moves one instance would
// otherwise widen every fragment in the scene back to its whole triangle.
#pragma once
#include <vector>

#include "exitance/runtime/core/bvh4.h"
#include "exitance/runtime/vec_math.h"

namespace exitance {

// `positions`: 3 vertices per triangle (Scene::positions); `fitted_to`: the positions the boxes were
// fitted to (the build's or the last refit's; the same size), or null to refit every leaf. Throws
// std::invalid_argument when a leaf slot names a triangle `positions` does not have, a child word
// names a node that does not come after its parent (the depth-first layout every builder here
// writes), or `fitted_to` has another size; `bvh` is unchanged then.
void refit_bvh4(Bvh4& bvh, const std::vector<Vec3>& positions, const std::vector<Vec3>* fitted_to = nullptr);

}  // namespace exitance
