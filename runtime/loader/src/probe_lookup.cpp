#include "probe_lookup.h"

#include <algorithm>
#include <cmath>

#include "exitance/runtime/spherical_harmonics.h"

namespace exitance::loader {
namespace {

struct AxisCell {
  uint32_t i0, i1;
  float t;  // weight of i1
};

AxisCell axis_cell(float position, float origin, float spacing, uint32_t count) {
  if (count == 1) return {0, 0, 0.0f};
  const double g = std::clamp((double(position) - origin) / spacing, 0.0, double(count - 1));
  const uint32_t i0 = std::min(uint32_t(g), count - 2);
  return {i0, i0 + 1, float(g - i0)};
}

}  // namespace

ProbeShResult interpolate_probe_sh(const formats::ProbeGrid& grid, Point3 point) {
  AxisCell cell[3];
  for (int a = 0; a < 3; ++a) cell[a] = axis_cell(point[a], grid.origin[a], grid.spacing[a], grid.counts[a]);

  // Accumulate in double: the weights are renormalised, and a weight of a few ulps must not dominate.
  double sum[27] = {}, equal_sum[27] = {};
  double weight_sum = 0;
  int usable_corners = 0;
  for (int corner = 0; corner < 8; ++corner) {
    uint32_t index[3];
    double weight = 1;
    for (int a = 0; a < 3; ++a) {
      const bool upper = (corner >> a) & 1;
      index[a] = upper ? cell[a].i1 : cell[a].i0;
      weight *= upper ? cell[a].t : 1.0 - cell[a].t;
    }
    const formats::ProbeRecord& probe = grid.probes[grid.index(index[0], index[1], index[2])];
    if (!formats::probe_is_usable(probe)) continue;
    ++usable_corners;
    weight_sum += weight;
    for (int k = 0; k < 27; ++k) {
      sum[k] += weight * probe.sh[k];
      equal_sum[k] += probe.sh[k];
    }
  }

  ProbeShResult result;
  if (usable_corners == 0) return result;
  result.usable = true;
  const bool use_trilinear = weight_sum > 0;
  const double scale = use_trilinear ? 1.0 / weight_sum : 1.0 / usable_corners;
  for (int k = 0; k < 27; ++k) result.sh[k / 3][k % 3] = float((use_trilinear ? sum[k] : equal_sum[k]) * scale);
  return result;
}

ProbeIrradianceResult probe_irradiance_over_pi(const formats::ProbeGrid& grid, Point3 point, Point3 normal) {
  const ProbeShResult sh = interpolate_probe_sh(grid, point);
  ProbeIrradianceResult result;
  if (!sh.usable) return result;
  ShRgb radiance;
  for (int i = 0; i < kShCoefficients; ++i) radiance[i] = {sh.sh[i][0], sh.sh[i][1], sh.sh[i][2]};
  // Normalised in double so very small or very large (finite, non-zero) normals stay well defined.
  const double length = std::sqrt(double(normal[0]) * normal[0] + double(normal[1]) * normal[1] + double(normal[2]) * normal[2]);
  const Vec3 n{float(normal[0] / length), float(normal[1] / length), float(normal[2] / length)};
  const Vec3 e = sh_irradiance_over_pi(radiance, n);
  result.irradiance_over_pi = {e.x, e.y, e.z};
  result.usable = true;
  return result;
}

}  // namespace exitance::loader
