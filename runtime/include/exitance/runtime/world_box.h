// An axis-aligned box in world space, and the boxes of a scene's triangles: what edits, refits and
// probe placement measure distances and extents against.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "exitance/runtime/scene.h"
#include "exitance/runtime/vec_math.h"

namespace exitance {

struct WorldBox {
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};  // empty until grown

  void grow(Vec3 p) { lo = min(lo, p), hi = max(hi, p); }
  void grow(const WorldBox& b) { lo = min(lo, b.lo), hi = max(hi, b.hi); }
  bool empty() const { return !(lo.x <= hi.x); }
  float half_diagonal() const { return empty() ? 0.0f : 0.5f * length(hi - lo); }
  // Squared distance from p to the box (0 inside).
  float distance_squared(Vec3 p) const {
    const float dx = std::max({lo.x - p.x, 0.0f, p.x - hi.x});
    const float dy = std::max({lo.y - p.y, 0.0f, p.y - hi.y});
    const float dz = std::max({lo.z - p.z, 0.0f, p.z - hi.z});
    return dx * dx + dy * dy + dz * dz;
  }
  // p lies in the box grown by `margin` on every side.
  bool contains(Vec3 p, float margin) const {
    return p.x >= lo.x - margin && p.x <= hi.x + margin && p.y >= lo.y - margin && p.y <= hi.y + margin &&
           p.z >= lo.z - margin && p.z <= hi.z + margin;
  }
};

// The box of triangles [first, first + count) of the scene's world-space triangle soup.
inline WorldBox triangles_world_box(const Scene& scene, uint32_t first, uint32_t count) {
  WorldBox box;
  for (size_t v = size_t(first) * 3; v < (size_t(first) + count) * 3; ++v) box.grow(scene.positions[v]);
  return box;
}

inline WorldBox instance_world_box(const Scene& scene, const Instance& instance) {
  return triangles_world_box(scene, instance.first_triangle, instance.triangle_count);
}

inline WorldBox scene_world_box(const Scene& scene) {
  return triangles_world_box(scene, 0, uint32_t(scene.triangle_count()));
}

}  // namespace exitance
