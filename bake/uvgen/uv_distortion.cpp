#include "uv_distortion.h"

#include <algorithm>
#include <cmath>

namespace exitance::uvgen {
namespace {

constexpr double kCap = 1e6;  // a collapsed UV triangle: large, never infinite

double capped(double x) { return std::isfinite(x) ? std::min(x, kCap) : kCap; }

}  // namespace

TriangleDistortion triangle_distortion(const std::array<std::array<double, 3>, 3>& p,
                                       const std::array<std::array<double, 2>, 3>& uv, double uv_to_3d_scale) {
  // The 3-D triangle in its own plane: p0 at the origin, p1 on the x axis.
  double e1[3], e2[3];
  for (int k = 0; k < 3; ++k) e1[k] = p[1][k] - p[0][k], e2[k] = p[2][k] - p[0][k];
  const double length1 = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  if (!(length1 > 0)) return {};
  const double bx = (e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2]) / length1;
  const double cross[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  const double by = std::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]) / length1;
  if (!(by > 0)) return {};
  // J maps the plane triangle's edges (length1, 0), (bx, by) to the UV edges: J = U P^-1.
  const double u1 = (uv[1][0] - uv[0][0]) * uv_to_3d_scale, v1 = (uv[1][1] - uv[0][1]) * uv_to_3d_scale;
  const double u2 = (uv[2][0] - uv[0][0]) * uv_to_3d_scale, v2 = (uv[2][1] - uv[0][1]) * uv_to_3d_scale;
  // P^-1 = [[1/length1, -bx/(length1 by)], [0, 1/by]]
  const double j00 = u1 / length1, j01 = (u2 - u1 * bx / length1) / by;
  const double j10 = v1 / length1, j11 = (v2 - v1 * bx / length1) / by;
  // Singular values of a 2x2 matrix in closed form.
  const double e = 0.5 * (j00 + j11), f = 0.5 * (j00 - j11), g = 0.5 * (j10 + j01), h = 0.5 * (j10 - j01);
  const double q = std::sqrt(e * e + h * h), r = std::sqrt(f * f + g * g);
  const double s1 = q + r, s2 = std::fabs(q - r);
  TriangleDistortion d;
  const double area_ratio = s1 * s2;
  d.area = area_ratio > 0 ? capped(std::max(area_ratio, 1 / area_ratio)) : kCap;
  d.angle = s2 > 0 ? capped(s1 / s2) : kCap;
  return d;
}

}  // namespace exitance::uvgen
