#include "exitance/runtime/core/bvh4_refit.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "exitance/runtime/world_box.h"

namespace exitance {

void refit_bvh4(Bvh4& bvh, const std::vector<Vec3>& positions, const std::vector<Vec3>* fitted_to) {
  const size_t triangle_count = positions.size() / 3;
  if (fitted_to && fitted_to->size() != positions.size())
    throw std::invalid_argument("refit_bvh4: " + std::to_string(fitted_to->size()) + " fitted positions for " +
                                std::to_string(positions.size()));
  for (uint32_t t : bvh.leaf_triangles)
    if (t >= triangle_count)
      throw std::invalid_argument("refit_bvh4: leaf references triangle " + std::to_string(t) + " of " +
                                  std::to_string(triangle_count));
  for (size_t n = 0; n < bvh.nodes.size(); ++n)
    for (uint32_t child : bvh.nodes[n].child) {
      if (child == kBvhEmptyChild) continue;
      if (child & kBvhLeafBit) {
        const uint32_t first = (child & ~kBvhLeafBit) >> 2, count = (child & 3u) + 1;
        if (size_t(first) + count > bvh.leaf_triangles.size())
          throw std::invalid_argument("refit_bvh4: node " + std::to_string(n) + " has a leaf past the last slot");
      } else if (child <= n || child >= bvh.nodes.size()) {
        throw std::invalid_argument("refit_bvh4: node " + std::to_string(n) + " has child " + std::to_string(child) +
                                    " (children come after their parent)");
      }
    }
  // Per triangle: whether a vertex moved since the boxes were fitted (all of them without `fitted_to`).
  std::vector<uint8_t> moved(triangle_count, 1);
  if (fitted_to)
    for (size_t t = 0; t < triangle_count; ++t) {
      bool same = true;
      for (size_t k = 0; k < 3; ++k) {
        const Vec3 a = positions[t * 3 + k], b = (*fitted_to)[t * 3 + k];
        same = same && a.x == b.x && a.y == b.y && a.z == b.z;
      }
      moved[t] = same ? 0 : 1;
    }
  // Children come after their parents: one pass from the last node up sees every child's box first.
  std::vector<WorldBox> node_box(bvh.nodes.size());
  for (size_t n = bvh.nodes.size(); n-- > 0;) {
    Bvh4Node& node = bvh.nodes[n];
    for (int i = 0; i < 4; ++i) {
      const uint32_t child = node.child[i];
      if (child == kBvhEmptyChild) continue;  // its box stays the builder's empty one
      WorldBox box;
      if (child & kBvhLeafBit) {
        const uint32_t first = (child & ~kBvhLeafBit) >> 2, count = (child & 3u) + 1;
        bool leaf_moved = false;
        for (uint32_t s = first; s < first + count; ++s) leaf_moved = leaf_moved || moved[bvh.leaf_triangles[s]];
        if (leaf_moved) {
          for (uint32_t s = first; s < first + count; ++s)
            for (int k = 0; k < 3; ++k) box.grow(positions[size_t(bvh.leaf_triangles[s]) * 3 + size_t(k)]);
        } else {  // as fitted (a split fragment's box stays the fragment's)
          box.grow(Vec3{node.lo_x[i], node.lo_y[i], node.lo_z[i]});
          box.grow(Vec3{node.hi_x[i], node.hi_y[i], node.hi_z[i]});
        }
      } else {
        box = node_box[child];
      }
      node.lo_x[i] = box.lo.x, node.lo_y[i] = box.lo.y, node.lo_z[i] = box.lo.z;
      node.hi_x[i] = box.hi.x, node.hi_y[i] = box.hi.y, node.hi_z[i] = box.hi.z;
      node_box[n].grow(box);
    }
  }
}

}  // namespace exitance
