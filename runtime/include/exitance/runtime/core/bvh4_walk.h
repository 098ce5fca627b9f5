// The closest-hit walk over a BVH4 in the GPU layout (bvh4.h), header-only and standard library
// only, so that code which must not link the lighting core (exitance-view: the loader and
// scene.bin's records alone) casts rays with the very walk the runtime uses for its host rays
// (core/bvh4_closest_hit.cpp). Templated on the node type: Bvh4Node and scene.bin's BvhNodeRecord
// have the same fields. Double-precision slab tests and Moller-Trumbore per triangle; not the GPU's
// watertight test, so on an edge or a vertex it may report either triangle.
#pragma once
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "exitance/runtime/core/bvh4.h"
#include "exitance/runtime/vec_math.h"

namespace exitance {

struct Bvh4WalkHit {
  bool found = false;
  double distance = 0;
  uint32_t triangle = 0;
  double b1 = 0, b2 = 0;  // barycentric weights of corners 1 and 2 at the hit
};

struct TriangleIntersection {
  double distance = -1;  // negative: a miss
  double b1 = 0, b2 = 0;
};

// Distance along the ray to the triangle and the barycentrics there; distance < 0 on a miss.
inline TriangleIntersection intersect_triangle(const Vec3& o, const Vec3& d, const Vec3& p0, const Vec3& p1,
                                               const Vec3& p2) {
  const double e1[3] = {double(p1.x) - p0.x, double(p1.y) - p0.y, double(p1.z) - p0.z};
  const double e2[3] = {double(p2.x) - p0.x, double(p2.y) - p0.y, double(p2.z) - p0.z};
  const double dd[3] = {d.x, d.y, d.z};
  const double p[3] = {dd[1] * e2[2] - dd[2] * e2[1], dd[2] * e2[0] - dd[0] * e2[2], dd[0] * e2[1] - dd[1] * e2[0]};
  const double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
  if (det == 0) return {};
  const double s[3] = {double(o.x) - p0.x, double(o.y) - p0.y, double(o.z) - p0.z};
  const double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
  if (u < 0 || u > 1) return {};
  const double q[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]};
  const double v = (dd[0] * q[0] + dd[1] * q[1] + dd[2] * q[2]) / det;
  if (v < 0 || u + v > 1) return {};
  return {(e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det, u, v};
}

// The nearest triangle hit at a distance in (0, t_max]. `corners(t, p0, p1, p2)` fills triangle t's
// corners; `stack` is scratch space (reused across calls to spare allocations).
// kNearestChildFirst visits a node's children in the order the ray enters their boxes (leaves
// first), so the closest hit is found early and shrinks the search: faster for long rays (views),
// the same hit unless two triangles are equally near (the runtime's host rays keep storage order).
template <bool kNearestChildFirst = false, class Node, class Corners>
Bvh4WalkHit bvh4_closest_hit(const Node* nodes, size_t node_count, const uint32_t* leaf_triangles, const Corners& corners,
                             const Vec3& origin, const Vec3& direction, float t_max, std::vector<uint32_t>& stack) {
  Bvh4WalkHit best;
  if (node_count == 0) return best;
  double best_t = t_max;
  const double inv[3] = {1.0 / double(direction.x), 1.0 / double(direction.y), 1.0 / double(direction.z)};
  const double o[3] = {origin.x, origin.y, origin.z};
  const auto intersect_leaf = [&](uint32_t child) {
    const uint32_t first = (child & ~kBvhLeafBit) >> 2, count = (child & 3u) + 1;
    for (uint32_t slot = first; slot < first + count; ++slot) {
      const uint32_t t = leaf_triangles[slot];
      Vec3 p0, p1, p2;
      corners(t, p0, p1, p2);
      const TriangleIntersection hit = intersect_triangle(origin, direction, p0, p1, p2);
      if (hit.distance > 0 && hit.distance <= best_t) {
        best_t = hit.distance;
        best = {true, hit.distance, t, hit.b1, hit.b2};
      }
    }
  };
  stack.assign(1, 0);
  while (!stack.empty()) {
    const Node& node = nodes[stack.back()];
    stack.pop_back();
    struct Entered {
      double distance;
      uint32_t child;
    } entered[4];
    int entered_count = 0;
    for (int c = 0; c < 4; ++c) {
      const uint32_t child = node.child[c];
      if (child == kBvhEmptyChild) continue;
      // Slab test in double (inf * 0 is NaN: the comparisons then fail towards "keep", which is safe).
      const double lo[3] = {node.lo_x[c], node.lo_y[c], node.lo_z[c]}, hi[3] = {node.hi_x[c], node.hi_y[c], node.hi_z[c]};
      double enter = 0, leave = best_t;
      for (int a = 0; a < 3; ++a) {
        double t0 = (lo[a] - o[a]) * inv[a], t1 = (hi[a] - o[a]) * inv[a];
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > enter) enter = t0;
        if (t1 < leave) leave = t1;
      }
      if (enter > leave) continue;
      if constexpr (kNearestChildFirst) {
        entered[entered_count++] = {enter, child};
      } else if (!(child & kBvhLeafBit)) {
        stack.push_back(child);
      } else {
        intersect_leaf(child);
      }
    }
    if constexpr (kNearestChildFirst) {
      // Insertion sort by entry distance (at most 4), then leaves nearest first, then inner
      // children pushed farthest first so the nearest is popped next.
      for (int i = 1; i < entered_count; ++i)
        for (int j = i; j > 0 && entered[j].distance < entered[j - 1].distance; --j) std::swap(entered[j], entered[j - 1]);
      for (int i = 0; i < entered_count; ++i)
        if (entered[i].child & kBvhLeafBit) intersect_leaf(entered[i].child);
      for (int i = entered_count - 1; i >= 0; --i)
        if (!(entered[i].child & kBvhLeafBit) && entered[i].distance <= best_t) stack.push_back(entered[i].child);
    }
  }
  return best;
}

}  // namespace exitance
