// Distortion of a flattening: per triangle the singular values s1 >= s2 of the linear map from the
// 3-D triangle to its UV triangle, with UVs scaled so that the mesh's UV area equals its 3-D area.
#pragma once
#include <array>

namespace exitance::uvgen {

struct TriangleDistortion {
  double area = 1;   // max(s1 s2, 1 / (s1 s2)), capped at 1e6 (a collapsed UV triangle)
  double angle = 1;  // s1 / s2, capped at 1e6
};

TriangleDistortion triangle_distortion(const std::array<std::array<double, 3>, 3>& p,
                                       const std::array<std::array<double, 2>, 3>& uv, double uv_to_3d_scale);

}  // namespace exitance::uvgen
