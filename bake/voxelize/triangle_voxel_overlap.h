// The triangle/box separating-axis test of triangle_box_overlap.h specialised to the unit cells
// of a voxel grid, with everything that depends only on the triangle computed once (Schwarz and
// Seidel 2010, "Fast parallel surface and solid voxelization on GPUs", §3.1). The nine edge axes
// become three 2D edge-function tests, one per coordinate-plane projection, and the plane-normal
// axis becomes an interval test; the cell's own axes are the caller's loop bounds. Cell (x, y, z)
// is the closed box [x, x+1] × [y, y+1] × [z, z+1] in grid units.
#pragma once
#include <cmath>

#include "triangle_box_overlap.h"

namespace exitance {

class TriangleVoxelOverlap {
 public:
  // Vertices in grid units (voxel edge = 1).
  TriangleVoxelOverlap(const Double3& a, const Double3& b, const Double3& c) {
    const Double3 v[3] = {a, b, c};
    normal_ = cross(b - a, c - a);
    // Plane axis: the cell overlaps the plane when n·v0 lies between n·(cell corner nearest along -n)
    // and n·(corner farthest along n); those corners are cell + near_corner_ and cell + far_corner_.
    plane_offset_ = dot(normal_, a);
    for (int k = 0; k < 3; ++k) {
      near_corner_[k] = normal_[k] > 0 ? 0.0 : 1.0;
      far_corner_[k] = 1.0 - near_corner_[k];
    }
    // Edge axes: in the projection dropping axis `drop`, with (p, q) the two remaining axes in cyclic
    // order, the cell must reach the inner side of every edge's 2D line. Orienting the edge normals
    // by the sign of n[drop] makes "inner" the same side for either winding.
    for (int drop = 0; drop < 3; ++drop) {
      const int p = (drop + 1) % 3, q = (drop + 2) % 3;
      const double orientation = normal_[drop] >= 0 ? 1.0 : -1.0;
      for (int e = 0; e < 3; ++e) {
        const Double3& from = v[e];
        const Double3& to = v[(e + 1) % 3];
        EdgeFunction& f = edges_[drop][e];
        f.np = -(to[q] - from[q]) * orientation;
        f.nq = (to[p] - from[p]) * orientation;
        // Evaluated at the cell's corner farthest along the edge normal (the critical point).
        f.offset = -(f.np * from[p] + f.nq * from[q]) + std::max(0.0, f.np) + std::max(0.0, f.nq);
      }
    }
  }

  const Double3& normal() const { return normal_; }

  // The projection onto the plane orthogonal to `drop` reaches the 2D cell whose minimum corner is
  // (cell_p, cell_q), the coordinates along axes (drop+1)%3 and (drop+2)%3.
  bool projection_overlaps(int drop, double cell_p, double cell_q) const {
    for (const EdgeFunction& f : edges_[drop])
      if (f.np * cell_p + f.nq * cell_q + f.offset < 0) return false;
    return true;
  }

  bool plane_overlaps(const Double3& cell) const {
    const double near = normal_[0] * (cell[0] + near_corner_[0]) + normal_[1] * (cell[1] + near_corner_[1]) +
                        normal_[2] * (cell[2] + near_corner_[2]);
    const double far = normal_[0] * (cell[0] + far_corner_[0]) + normal_[1] * (cell[1] + far_corner_[1]) +
                       normal_[2] * (cell[2] + far_corner_[2]);
    return near <= plane_offset_ && plane_offset_ <= far;
  }

  // The full test for a cell inside the triangle's bounding box (the caller's loop guarantees the
  // three box axes).
  bool overlaps(const Double3& cell) const {
    return plane_overlaps(cell) && projection_overlaps(0, cell[1], cell[2]) && projection_overlaps(1, cell[2], cell[0]) &&
           projection_overlaps(2, cell[0], cell[1]);
  }

 private:
  struct EdgeFunction {
    double np = 0, nq = 0, offset = 0;
  };
  Double3 normal_;
  double plane_offset_ = 0;
  Double3 near_corner_{}, far_corner_{};
  EdgeFunction edges_[3][3];
};

}  // namespace exitance
