// The input mesh with vertices welded by position, so a mesh exported with split vertices at every
// normal or UV seam still has its triangles connected; face normals and areas in double.
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "exitance/runtime/vec_math.h"

namespace exitance::uvgen {

using Point3 = std::array<double, 3>;

struct WeldedMesh {
  std::vector<Point3> positions;                  // one per distinct input position
  std::vector<std::array<uint32_t, 3>> triangles;  // welded vertex of each input corner
  std::vector<Point3> normals;                    // unit face normals; zero for degenerate faces
  std::vector<double> areas;                      // 3-D face areas
  std::vector<uint8_t> degenerate;                // zero area (relative to the mesh's size) or a repeated vertex

  size_t triangle_count() const { return triangles.size(); }
};

// Throws std::invalid_argument when an index is out of range. Non-finite positions make their
// triangles degenerate.
WeldedMesh weld_by_position(std::span<const Vec3> positions, std::span<const uint32_t> indices);

}  // namespace exitance::uvgen
