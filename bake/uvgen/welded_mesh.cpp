#include "welded_mesh.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace exitance::uvgen {
namespace {

// Faces whose area is below this fraction of the squared bounding-box diagonal have no usable
// normal: float positions cannot resolve them.
constexpr double kDegenerateAreaFraction = 1e-14;

bool finite(const Vec3& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

}  // namespace

WeldedMesh weld_by_position(std::span<const Vec3> positions, std::span<const uint32_t> indices) {
  for (size_t i = 0; i < indices.size(); ++i)
    if (indices[i] >= positions.size())
      throw std::invalid_argument("index " + std::to_string(indices[i]) + " at " + std::to_string(i) +
                                  " is out of range (" + std::to_string(positions.size()) + " vertices)");
  WeldedMesh mesh;
  // Sort vertex numbers by position (then number, so equal positions keep a fixed order); equal
  // positions get one welded vertex. -0.0 and 0.0 compare equal, so they weld.
  std::vector<uint32_t> order(positions.size());
  std::iota(order.begin(), order.end(), 0u);
  auto key = [&](uint32_t v) { return std::array<float, 3>{positions[v].x, positions[v].y, positions[v].z}; };
  auto less = [&](uint32_t a, uint32_t b) {
    const bool fa = finite(positions[a]), fb = finite(positions[b]);
    if (fa != fb) return fa;  // finite first; every non-finite vertex stays alone
    if (fa) {
      const auto ka = key(a), kb = key(b);
      if (ka != kb) return ka < kb;
    }
    return a < b;
  };
  std::sort(order.begin(), order.end(), less);
  std::vector<uint32_t> welded(positions.size());
  for (size_t i = 0; i < order.size(); ++i) {
    const uint32_t v = order[i];
    const bool same = i > 0 && finite(positions[v]) && finite(positions[order[i - 1]]) && key(v) == key(order[i - 1]);
    if (!same) {
      const Vec3& p = positions[v];
      mesh.positions.push_back(finite(p) ? Point3{p.x, p.y, p.z} : Point3{0, 0, 0});
    }
    welded[v] = uint32_t(mesh.positions.size() - 1);
  }

  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (const Vec3& p : positions)
    if (finite(p))
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], double(p[k])), hi[k] = std::max(hi[k], double(p[k]));
  double diagonal2 = 0;
  for (int k = 0; k < 3; ++k) diagonal2 += hi[k] > lo[k] ? (hi[k] - lo[k]) * (hi[k] - lo[k]) : 0;
  const double min_area = kDegenerateAreaFraction * diagonal2;

  const size_t count = indices.size() / 3;
  mesh.triangles.resize(count);
  mesh.normals.assign(count, Point3{0, 0, 0});
  mesh.areas.assign(count, 0);
  mesh.degenerate.assign(count, 1);
  for (size_t t = 0; t < count; ++t) {
    bool all_finite = true;
    for (int k = 0; k < 3; ++k) {
      mesh.triangles[t][k] = welded[indices[3 * t + k]];
      all_finite = all_finite && finite(positions[indices[3 * t + k]]);
    }
    const auto& [a, b, c] = mesh.triangles[t];
    if (!all_finite || a == b || b == c || a == c) continue;
    const Point3 &p0 = mesh.positions[a], &p1 = mesh.positions[b], &p2 = mesh.positions[c];
    const double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
    const double e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double area = 0.5 * length;
    if (!(area > min_area) || !std::isfinite(area)) continue;
    mesh.areas[t] = area;
    mesh.normals[t] = {n[0] / length, n[1] / length, n[2] / length};
    mesh.degenerate[t] = 0;
  }
  return mesh;
}

}  // namespace exitance::uvgen
