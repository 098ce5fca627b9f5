// Refitting the BVH4 after geometry moved (runtime scene edits, refresh/scene_edits.h): the tree's
// topology and leaf slots stay as the offline stage built them, only the child boxes are
// recomputed bottom-up from the triangles' current vertices, each inner box the min/max of its
// children's, so every part of a triangle a leaf refers to lies inside every box above it
// (traversal stays correct); the tree's quality degrades as instances move far from where it was
// built, which only costs speed.
//
// Without the positions the boxes were fitted to, every leaf boxes the float min/max of its
// triangles' vertices and every inner box is its children's union. With them, only the leaves that
// hold a moved triangle and the nodes above them change (an edit that moves one instance costs its
// own triangles and their paths to the root, not a pass over the scene): such a leaf boxes each of
// its triangles' part in its old box carried to where the triangle went (rounded outward), since
// the spatial-split builder's leaf boxes hold a clipped fragment of a triangle, tighter than the
// triangle's bounds, and would otherwise widen back to the whole triangle; each node above becomes
// its children's union; every other box stays as it was.
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

constexpr uint32_t kNoBvhLink = 0xFFFFFFFFu;

// Where each leaf slot and node hangs in the tree and which slots hold each triangle: what a refit
// of a few moved triangles walks instead of the whole tree. Valid while the topology stays (refits
// keep it). Throws std::invalid_argument as refit_bvh4 does for a malformed tree.
struct Bvh4Links {
  std::vector<uint32_t> slot_leaf;    // per leaf slot: node * 4 + child of the leaf that holds it
  std::vector<uint32_t> node_parent;  // per node: parent * 4 + child, the root kNoBvhLink
  std::vector<uint32_t> triangle_slot_start, triangle_slots;  // per triangle t: its slots, [start[t], start[t + 1])
};
Bvh4Links link_bvh4(const Bvh4& bvh, size_t triangle_count);

// refit_bvh4 with fitted positions, given what moved: `moved` ascending triangle indices,
// `moved_before` their 3 vertices each as the boxes were fitted to (in that order), `positions`
// every triangle's vertices now. The same boxes as refit_bvh4(bvh, positions, fitted_to) for a
// fitted_to that differs in those triangles. Returns the nodes whose records changed, ascending.
std::vector<uint32_t> refit_bvh4_moved(Bvh4& bvh, const Bvh4Links& links, const std::vector<Vec3>& positions,
                                       const std::vector<uint32_t>& moved, const std::vector<Vec3>& moved_before);

}  // namespace exitance
