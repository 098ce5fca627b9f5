// Cells of a triangle's bounding box that lie wholly outside one of its edges by a margin, told
// apart without clipping (most of a thin or diagonal triangle's box): the raster skips them. The
// margin, 0.01 texel, is far above the clip's float error (a few ulps of coordinates up to the
// page size, 2048: ~5e-4 texel), so clipped_texel_coverage, with the same edges and orientation,
// finds no area there (tests/unit/layout_and_raster_test.cpp) and skipping them changes nothing.
// Edge functions in double, the orientation as the clip takes it.
#pragma once

#include <algorithm>
#include <cmath>

#include "exitance/runtime/vec_math.h"

namespace exitance {

class CellRejection {
 public:
  explicit CellRejection(const Vec2 tri[3]) {
    const Vec2 e1 = tri[1] - tri[0], e2 = tri[2] - tri[0];
    const double orientation = (e1.x * e2.y - e1.y * e2.x) >= 0 ? 1.0 : -1.0;
    for (int k = 0; k < 3; ++k) {
      const Vec2 a = tri[k], b = tri[(k + 1) % 3];
      // side(p) = orientation * ((b - a) x (p - a)) = A p.x + B p.y + C: >= 0 on the kept side.
      const double dx = double(b.x) - a.x, dy = double(b.y) - a.y;
      edges_[k].a = -orientation * dy;
      edges_[k].b = orientation * dx;
      edges_[k].c = orientation * (dy * a.x - dx * a.y);
      edges_[k].margin = -0.01 * std::sqrt(dx * dx + dy * dy);
    }
  }
  // Whether the cell [x, x + 1] x [y, y + 1] lies outside some edge by more than the margin.
  bool rejects(int x, int y) const {
    for (const Edge& e : edges_) {
      const double highest = e.a * x + e.b * y + e.c + std::max(e.a, 0.0) + std::max(e.b, 0.0);  // best corner
      if (highest < e.margin) return true;
    }
    return false;
  }

 private:
  struct Edge {
    double a = 0, b = 0, c = 0, margin = 0;
  };
  Edge edges_[3];
};

}  // namespace exitance
