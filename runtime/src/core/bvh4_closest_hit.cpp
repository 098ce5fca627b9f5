#include "exitance/runtime/core/bvh4_closest_hit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace exitance {
namespace {

Vec3 xyz(const vec4& v) { return {v.x, v.y, v.z}; }

// Distance along the ray to the triangle, or a negative value when it misses.
double intersect(const Vec3& o, const Vec3& d, const Vec3& p0, const Vec3& p1, const Vec3& p2) {
  const double e1[3] = {double(p1.x) - p0.x, double(p1.y) - p0.y, double(p1.z) - p0.z};
  const double e2[3] = {double(p2.x) - p0.x, double(p2.y) - p0.y, double(p2.z) - p0.z};
  const double dd[3] = {d.x, d.y, d.z};
  const double p[3] = {dd[1] * e2[2] - dd[2] * e2[1], dd[2] * e2[0] - dd[0] * e2[2], dd[0] * e2[1] - dd[1] * e2[0]};
  const double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
  if (det == 0) return -1;
  const double s[3] = {double(o.x) - p0.x, double(o.y) - p0.y, double(o.z) - p0.z};
  const double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
  if (u < 0 || u > 1) return -1;
  const double q[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]};
  const double v = (dd[0] * q[0] + dd[1] * q[1] + dd[2] * q[2]) / det;
  if (v < 0 || u + v > 1) return -1;
  return (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
}

}  // namespace

BvhHit closest_hit(const LightingScene& scene, const Vec3& origin, const Vec3& direction, float t_max) {
  BvhHit best;
  const Bvh4& bvh = scene.bvh;
  if (bvh.nodes.empty()) return best;
  double best_t = t_max;
  const double inv[3] = {1.0 / double(direction.x), 1.0 / double(direction.y), 1.0 / double(direction.z)};
  const double o[3] = {origin.x, origin.y, origin.z};
  std::vector<uint32_t> stack{0};
  while (!stack.empty()) {
    const Bvh4Node& node = bvh.nodes[stack.back()];
    stack.pop_back();
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
      if (!(child & kBvhLeafBit)) {
        stack.push_back(child);
        continue;
      }
      const uint32_t first = (child & ~kBvhLeafBit) >> 2, count = (child & 3u) + 1;
      for (uint32_t slot = first; slot < first + count; ++slot) {
        const uint32_t t = bvh.leaf_triangles[slot];
        const GpuTriangle& tri = scene.triangles[t];
        const Vec3 p0 = xyz(tri.p0_material), p1 = xyz(tri.p1_area_pdf), p2 = xyz(tri.p2_instance);
        const double distance = intersect(origin, direction, p0, p1, p2);
        if (distance > 0 && distance <= best_t) {
          best_t = distance;
          best.found = true;
          best.distance = float(distance);
          best.triangle = t;
          best.geometric_normal = normalize(cross(p1 - p0, p2 - p0));
        }
      }
    }
  }
  return best;
}

}  // namespace exitance
