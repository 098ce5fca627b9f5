#include "exitance/runtime/core/bvh4_closest_hit.h"

#include <vector>

#include "exitance/runtime/core/bvh4_walk.h"

namespace exitance {
namespace {

Vec3 xyz(const vec4& v) { return {v.x, v.y, v.z}; }

}  // namespace

BvhHit closest_hit(const LightingScene& scene, const Vec3& origin, const Vec3& direction, float t_max) {
  const auto corners = [&](uint32_t t, Vec3& p0, Vec3& p1, Vec3& p2) {
    const GpuTriangle& tri = scene.triangles[t];
    p0 = xyz(tri.p0_material);
    p1 = xyz(tri.p1_emitter);
    p2 = xyz(tri.p2_instance);
  };
  // Per thread, kept between rays, not allocated per ray: the unocclude step after an edit traces
  // thousands of short rays per moved instance, on all cores.
  thread_local std::vector<uint32_t> stack;
  const Bvh4WalkHit walk = bvh4_closest_hit(scene.bvh.nodes.data(), scene.bvh.nodes.size(),
                                            scene.bvh.leaf_triangles.data(), corners, origin, direction, t_max, stack);
  BvhHit best;
  if (!walk.found) return best;
  Vec3 p0, p1, p2;
  corners(walk.triangle, p0, p1, p2);
  best.found = true;
  best.distance = float(walk.distance);
  best.triangle = walk.triangle;
  best.geometric_normal = normalize(cross(p1 - p0, p2 - p0));
  return best;
}

}  // namespace exitance
