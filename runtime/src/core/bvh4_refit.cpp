#include "exitance/runtime/core/bvh4_refit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance/runtime/float_rounding.h"
#include "exitance/runtime/world_box.h"

namespace exitance {
namespace {

using Point = std::array<double, 3>;

// The part of a triangle inside a box, as a polygon (Sutherland-Hodgman in double, points on the
// box's faces kept): it holds the part of the triangle a spatial-split leaf with that box refers to.
// Each of the 6 planes adds at most one corner: 9 at most, kept on the stack (a moved block clips
// thousands of triangles per edit).
struct ClippedPolygon {
  std::array<Point, 9> points;
  size_t count = 0;
  bool empty() const { return count == 0; }
  const Point* begin() const { return points.data(); }
  const Point* end() const { return points.data() + count; }
};

ClippedPolygon clip_to_box(const Vec3 triangle[3], const WorldBox& box) {
  ClippedPolygon polygon, next;
  polygon.count = 3;
  for (int i = 0; i < 3; ++i) polygon.points[size_t(i)] = {triangle[i].x, triangle[i].y, triangle[i].z};
  const double lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z};
  for (int axis = 0; axis < 3 && !polygon.empty(); ++axis)
    for (int side = 0; side < 2 && !polygon.empty(); ++side) {
      const double plane = side == 0 ? lo[axis] : hi[axis];
      auto inside = [&](const Point& p) { return side == 0 ? p[size_t(axis)] >= plane : p[size_t(axis)] <= plane; };
      next.count = 0;
      for (size_t i = 0; i < polygon.count; ++i) {
        const Point& a = polygon.points[i];
        const Point& b = polygon.points[(i + 1) % polygon.count];
        if (inside(a) && next.count < next.points.size()) next.points[next.count++] = a;
        if (inside(a) != inside(b) && next.count < next.points.size()) {
          const double t = (plane - a[size_t(axis)]) / (b[size_t(axis)] - a[size_t(axis)]);
          Point crossing;
          for (size_t k = 0; k < 3; ++k) crossing[k] = a[k] + t * (b[k] - a[k]);
          crossing[size_t(axis)] = plane;
          next.points[next.count++] = crossing;
        }
      }
      std::swap(polygon, next);
    }
  return polygon;
}

// Where the part of a triangle inside `box` went when the triangle's vertices moved from `before`
// to `after`: the part's corners carried by their barycentric coordinates, as a float box that
// holds them (one more float step outward than rounding gives, for the double arithmetic), within
// the moved triangle's bounds. The moved triangle's whole bounds where the part cannot be carried
// (a degenerate triangle, or no part left by the clip in double).
WorldBox carried_part_box(const Vec3 before[3], const Vec3 after[3], const WorldBox& box) {
  WorldBox whole;
  for (int k = 0; k < 3; ++k) whole.grow(after[k]);
  // A triangle wholly inside the box (no spatial split cut it): the clip keeps its three corners,
  // which carry to the moved corners, so its part is the whole moved triangle (most leaves).
  if (box.contains(before[0], 0.0f) && box.contains(before[1], 0.0f) && box.contains(before[2], 0.0f)) return whole;
  const ClippedPolygon part = clip_to_box(before, box);
  auto point = [](const Vec3& v) { return Point{v.x, v.y, v.z}; };
  auto minus = [](const Point& a, const Point& b) { return Point{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
  const Point v0 = point(before[0]), e1 = minus(point(before[1]), v0), e2 = minus(point(before[2]), v0);
  auto dot = [](const Point& a, const Point& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
  const double d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2);
  const double det = d11 * d22 - d12 * d12;
  // Nearly collinear vertices make the barycentric coordinates ill-conditioned: keep the whole bounds.
  if (part.empty() || !(det > 1e-10 * d11 * d22)) return whole;
  const Point w0 = point(after[0]), f1 = minus(point(after[1]), w0), f2 = minus(point(after[2]), w0);
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (const Point& p : part) {
    const Point r = minus(p, v0);
    const double r1 = dot(r, e1), r2 = dot(r, e2);
    const double b = (d22 * r1 - d12 * r2) / det, c = (d11 * r2 - d12 * r1) / det;
    for (size_t k = 0; k < 3; ++k) {
      const double q = w0[k] + b * f1[k] + c * f2[k];
      lo[k] = std::min(lo[k], q), hi[k] = std::max(hi[k], q);
    }
  }
  WorldBox carried;
  const float whole_lo[3] = {whole.lo.x, whole.lo.y, whole.lo.z}, whole_hi[3] = {whole.hi.x, whole.hi.y, whole.hi.z};
  float out_lo[3], out_hi[3];
  for (int k = 0; k < 3; ++k) {
    out_lo[k] = std::max(std::nextafter(float_at_or_below(lo[k]), -INFINITY), whole_lo[k]);
    out_hi[k] = std::min(std::nextafter(float_at_or_above(hi[k]), INFINITY), whole_hi[k]);
    if (!(out_lo[k] <= out_hi[k])) return whole;
  }
  carried.grow(Vec3{out_lo[0], out_lo[1], out_lo[2]});
  carried.grow(Vec3{out_hi[0], out_hi[1], out_hi[2]});
  return carried;
}

}  // namespace

Bvh4Links link_bvh4(const Bvh4& bvh, size_t triangle_count) {
  for (uint32_t t : bvh.leaf_triangles)
    if (t >= triangle_count)
      throw std::invalid_argument("refit_bvh4: leaf references triangle " + std::to_string(t) + " of " +
                                  std::to_string(triangle_count));
  Bvh4Links links;
  links.slot_leaf.assign(bvh.leaf_triangles.size(), kNoBvhLink);
  links.node_parent.assign(bvh.nodes.size(), kNoBvhLink);
  for (size_t n = 0; n < bvh.nodes.size(); ++n)
    for (uint32_t i = 0; i < 4; ++i) {
      const uint32_t child = bvh.nodes[n].child[i];
      if (child == kBvhEmptyChild) continue;
      if (child & kBvhLeafBit) {
        const uint32_t first = (child & ~kBvhLeafBit) >> 2, count = (child & 3u) + 1;
        if (size_t(first) + count > bvh.leaf_triangles.size())
          throw std::invalid_argument("refit_bvh4: node " + std::to_string(n) + " has a leaf past the last slot");
        for (uint32_t s = first; s < first + count; ++s) links.slot_leaf[s] = uint32_t(n) * 4 + i;
      } else if (child <= n || child >= bvh.nodes.size()) {
        throw std::invalid_argument("refit_bvh4: node " + std::to_string(n) + " has child " + std::to_string(child) +
                                    " (children come after their parent)");
      } else {
        links.node_parent[child] = uint32_t(n) * 4 + i;
      }
    }
  links.triangle_slot_start.assign(triangle_count + 1, 0);
  for (uint32_t t : bvh.leaf_triangles) ++links.triangle_slot_start[size_t(t) + 1];
  for (size_t t = 0; t < triangle_count; ++t) links.triangle_slot_start[t + 1] += links.triangle_slot_start[t];
  links.triangle_slots.resize(bvh.leaf_triangles.size());
  std::vector<uint32_t> next(links.triangle_slot_start.begin(), links.triangle_slot_start.end() - 1);
  for (uint32_t s = 0; s < uint32_t(bvh.leaf_triangles.size()); ++s) links.triangle_slots[next[bvh.leaf_triangles[s]]++] = s;
  return links;
}

namespace {

void set_child_box(Bvh4Node& node, int i, const WorldBox& box) {
  node.lo_x[i] = box.lo.x, node.lo_y[i] = box.lo.y, node.lo_z[i] = box.lo.z;
  node.hi_x[i] = box.hi.x, node.hi_y[i] = box.hi.y, node.hi_z[i] = box.hi.z;
}

WorldBox child_box(const Bvh4Node& node, int i) {
  return WorldBox{Vec3{node.lo_x[i], node.lo_y[i], node.lo_z[i]}, Vec3{node.hi_x[i], node.hi_y[i], node.hi_z[i]}};
}

// The union of a node's children's boxes: its box in its parent.
WorldBox node_union(const Bvh4Node& node) {
  WorldBox box;
  for (int i = 0; i < 4; ++i)
    if (node.child[i] != kBvhEmptyChild) box.grow(child_box(node, i));
  return box;
}

}  // namespace

std::vector<uint32_t> refit_bvh4_moved(Bvh4& bvh, const Bvh4Links& links, const std::vector<Vec3>& positions,
                                       const std::vector<uint32_t>& moved, const std::vector<Vec3>& moved_before) {
  const size_t triangle_count = positions.size() / 3;
  if (links.slot_leaf.size() != bvh.leaf_triangles.size() || links.node_parent.size() != bvh.nodes.size() ||
      links.triangle_slot_start.size() != triangle_count + 1)
    throw std::invalid_argument("refit_bvh4_moved: the links are not this tree's over these triangles");
  if (moved_before.size() != moved.size() * 3)
    throw std::invalid_argument("refit_bvh4_moved: " + std::to_string(moved_before.size()) + " positions before for " +
                                std::to_string(moved.size()) + " moved triangles");
  for (size_t k = 0; k < moved.size(); ++k)
    if (moved[k] >= triangle_count || (k > 0 && moved[k] <= moved[k - 1]))
      throw std::invalid_argument("refit_bvh4_moved: the moved triangles must ascend, each below " + std::to_string(triangle_count));
  // The leaves that hold a moved triangle, and the nodes above them.
  std::vector<uint32_t> leaves;
  for (uint32_t t : moved)
    for (uint32_t k = links.triangle_slot_start[t]; k < links.triangle_slot_start[size_t(t) + 1]; ++k)
      if (links.slot_leaf[links.triangle_slots[k]] != kNoBvhLink) leaves.push_back(links.slot_leaf[links.triangle_slots[k]]);
  std::sort(leaves.begin(), leaves.end());
  leaves.erase(std::unique(leaves.begin(), leaves.end()), leaves.end());
  auto before_of = [&](uint32_t t) -> const Vec3* {
    const auto it = std::lower_bound(moved.begin(), moved.end(), t);
    return it != moved.end() && *it == t ? &moved_before[size_t(it - moved.begin()) * 3] : &positions[size_t(t) * 3];
  };
  // Each triangle's part in the leaf's box, carried to where the triangle went: a split fragment of
  // a moved triangle stays a fragment. Leaves on threads (each reads its own box), written after.
  std::vector<WorldBox> leaf_box(leaves.size());
  for_each_chunk(leaves.size(), [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) {
      const Bvh4Node& node = bvh.nodes[leaves[k] / 4];
      const int i = int(leaves[k] % 4);
      const uint32_t first = (node.child[i] & ~kBvhLeafBit) >> 2, count = (node.child[i] & 3u) + 1;
      const WorldBox fitted = child_box(node, i);
      for (uint32_t s = first; s < first + count; ++s) {
        const uint32_t t = bvh.leaf_triangles[s];
        leaf_box[k].grow(carried_part_box(before_of(t), &positions[size_t(t) * 3], fitted));
      }
    }
  }, 64);  // a moved block's leaves over all cores (clipped fragments make some leaves costlier)
  std::vector<uint32_t> dirty;
  for (size_t k = 0; k < leaves.size(); ++k) {
    set_child_box(bvh.nodes[leaves[k] / 4], int(leaves[k] % 4), leaf_box[k]);
    dirty.push_back(leaves[k] / 4);
  }
  // Every node above a refit leaf, children before parents (a child's index exceeds its parent's).
  std::vector<uint8_t> marked(bvh.nodes.size(), 0);
  std::vector<uint32_t> above;
  for (uint32_t n : dirty)
    for (uint32_t at = n; !marked[at];) {
      marked[at] = 1;
      above.push_back(at);
      if (links.node_parent[at] == kNoBvhLink) break;
      at = links.node_parent[at] / 4;
    }
  std::sort(above.begin(), above.end(), std::greater<>());
  for (uint32_t n : above) {
    const uint32_t link = links.node_parent[n];
    if (link != kNoBvhLink) set_child_box(bvh.nodes[link / 4], int(link % 4), node_union(bvh.nodes[n]));
  }
  std::sort(above.begin(), above.end());
  return above;
}

void refit_bvh4(Bvh4& bvh, const std::vector<Vec3>& positions, const std::vector<Vec3>* fitted_to) {
  const size_t triangle_count = positions.size() / 3;
  if (fitted_to && fitted_to->size() != positions.size())
    throw std::invalid_argument("refit_bvh4: " + std::to_string(fitted_to->size()) + " fitted positions for " +
                                std::to_string(positions.size()));
  const Bvh4Links links = link_bvh4(bvh, triangle_count);
  if (fitted_to) {
    std::vector<uint32_t> moved;
    std::vector<Vec3> moved_before;
    for (size_t t = 0; t < triangle_count; ++t) {
      bool same = true;
      for (size_t k = 0; k < 3; ++k) {
        const Vec3 a = positions[t * 3 + k], b = (*fitted_to)[t * 3 + k];
        same = same && a.x == b.x && a.y == b.y && a.z == b.z;
      }
      if (same) continue;
      moved.push_back(uint32_t(t));
      for (size_t k = 0; k < 3; ++k) moved_before.push_back((*fitted_to)[t * 3 + k]);
    }
    refit_bvh4_moved(bvh, links, positions, moved, moved_before);
    return;
  }
  // Every leaf boxes its triangles' whole bounds; children come after their parents, so one pass
  // from the last node up sees every child's box first.
  std::vector<WorldBox> node_box(bvh.nodes.size());
  for (size_t n = bvh.nodes.size(); n-- > 0;) {
    Bvh4Node& node = bvh.nodes[n];
    for (int i = 0; i < 4; ++i) {
      const uint32_t child = node.child[i];
      if (child == kBvhEmptyChild) continue;  // its box stays the builder's empty one
      WorldBox box;
      if (child & kBvhLeafBit) {
        const uint32_t first = (child & ~kBvhLeafBit) >> 2, count = (child & 3u) + 1;
        for (uint32_t s = first; s < first + count; ++s)
          for (int k = 0; k < 3; ++k) box.grow(positions[size_t(bvh.leaf_triangles[s]) * 3 + size_t(k)]);
      } else {
        box = node_box[child];
      }
      set_child_box(node, i, box);
      node_box[n].grow(box);
    }
  }
}

}  // namespace exitance
