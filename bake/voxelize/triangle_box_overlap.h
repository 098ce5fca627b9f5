// Triangle/box overlap by the separating axis theorem (Akenine-Möller 2001, "Fast 3D triangle-box
// overlap testing"): the boxes are closed, so touching counts as overlap. This is the reference
// form, written for clarity; the voxelizer's inner loop uses the same 13 axes with per-triangle
// constants hoisted (triangle_voxel_overlap.h), and the tests check the two agree.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>

namespace exitance {

using Double3 = std::array<double, 3>;

inline Double3 operator-(const Double3& a, const Double3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline double dot(const Double3& a, const Double3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Double3 cross(const Double3& a, const Double3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// True when triangle (a, b, c) and the box centre ± half_size share at least one point.
inline bool triangle_overlaps_box(const Double3& box_centre, const Double3& half_size, const Double3& a,
                                  const Double3& b, const Double3& c) {
  const Double3 v[3] = {a - box_centre, b - box_centre, c - box_centre};
  // Separated along `axis` when the triangle's projection misses the box's projection [-r, r].
  auto separated_along = [&](const Double3& axis) {
    const double p0 = dot(axis, v[0]), p1 = dot(axis, v[1]), p2 = dot(axis, v[2]);
    const double r = half_size[0] * std::fabs(axis[0]) + half_size[1] * std::fabs(axis[1]) +
                     half_size[2] * std::fabs(axis[2]);
    return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
  };
  // 1. The box's face normals: the triangle's bounding box against the box.
  for (int k = 0; k < 3; ++k) {
    if (std::min({v[0][k], v[1][k], v[2][k]}) > half_size[k]) return false;
    if (std::max({v[0][k], v[1][k], v[2][k]}) < -half_size[k]) return false;
  }
  // 2. The triangle's plane normal.
  const Double3 edges[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
  if (separated_along(cross(edges[0], edges[1]))) return false;
  // 3. The nine cross products of box axes and triangle edges.
  for (const Double3& edge : edges)
    for (int k = 0; k < 3; ++k) {
      Double3 unit{0, 0, 0};
      unit[k] = 1;
      if (separated_along(cross(unit, edge))) return false;
    }
  return true;
}

}  // namespace exitance
