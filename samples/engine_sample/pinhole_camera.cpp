#include "pinhole_camera.h"

#include <cmath>

#include "engine_options.h"

namespace engine_sample {
namespace {

using Vec = std::array<double, 3>;

Vec sub(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double length(const Vec& a) { return std::sqrt(dot(a, a)); }
Vec scaled(const Vec& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }

// The nearest visible distance along the view direction, in scene units.
constexpr double kNear = 1e-3;

}  // namespace

std::array<float, 16> view_projection(const Vec& look_from, const Vec& look_at, const Vec& up, double yfov,
                                      uint32_t width, uint32_t height) {
  // The frame exitance-view builds (runtime/src/view/view_camera.cpp look_at_camera).
  const Vec view = sub(look_at, look_from);
  if (!(length(view) > 0)) throw UsageError("--look-at: equals --look-from (no view direction)");
  if (!(length(up) > 0)) throw UsageError("--up: is the zero vector");
  const Vec forward = scaled(view, 1 / length(view));
  const Vec side = cross(forward, scaled(up, 1 / length(up)));
  if (!(length(side) > 1e-6)) throw UsageError("--up: is parallel to the view direction");
  const Vec right = scaled(side, 1 / length(side));
  const Vec camera_up = cross(right, forward);
  const double tan_half = std::tan(yfov / 2), aspect = double(width) / double(height);
  // Rows of the matrix: x_clip, y_clip, z_clip, w_clip as functions of (world, 1).
  const Vec rx = scaled(right, 1 / (tan_half * aspect)), ry = scaled(camera_up, -1 / tan_half);
  const double rows[4][4] = {
      {rx[0], rx[1], rx[2], -dot(rx, look_from)},
      {ry[0], ry[1], ry[2], -dot(ry, look_from)},
      {0, 0, 0, kNear},
      {forward[0], forward[1], forward[2], -dot(forward, look_from)},
  };
  std::array<float, 16> m{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) m[size_t(c * 4 + r)] = float(rows[r][c]);
  return m;
}

}  // namespace engine_sample
