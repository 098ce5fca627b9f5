// Embree 3 BVH over the scene's triangle soup: closest hit and any hit for single rays.
#pragma once
#include <embree3/rtcore.h>

#include <functional>

#include "exitance/runtime/embree_device.h"
#include "exitance/runtime/scene.h"

namespace exitance {

struct Hit {
  bool found = false;
  float distance = 0;
  uint32_t triangle = 0;
  float b1 = 0, b2 = 0;     // barycentrics of vertices 1 and 2
  Vec3 geometric_normal;    // unit, from the winding (front side)
};

class EmbreeScene {
 public:
  explicit EmbreeScene(const Scene& scene);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  Hit intersect(Vec3 origin, Vec3 direction, float t_max) const;
  bool occluded(Vec3 origin, Vec3 direction, float t_max) const;
  // Whether any triangle hit within t_max along the ray satisfies `accept` (for scene checks, not
  // lighting). Every hit is offered to `accept` until one passes (an occlusion query whose filter
  // rejects the rest), so the answer does not depend on which of several equidistant hits the
  // CPU's Embree kernels would report as the closest.
  bool any_hit_where(Vec3 origin, Vec3 direction, float t_max, const std::function<bool(const Hit&)>& accept) const;
  // Distance from `point` to the nearest triangle (any side, any material), by Embree's point
  // query (rtcPointQuery); +infinity when no triangle is within `max_distance`.
  float distance_to_nearest_triangle(Vec3 point, float max_distance) const;
  // Whether some triangle within `radius` of `center` (by its closest point) passes `relevant`,
  // given the triangle's index and its three corners: an Embree point query that stops at the
  // first one, for tests that rule out every hit of a bundle of short rays in one BVH descent.
  bool any_triangle_within(Vec3 center, float radius,
                           const std::function<bool(uint32_t triangle, const Vec3* corners)>& relevant) const;
  // Largest side of the scene's bounding box: the scale of ray-offset error floors.
  float extent() const { return extent_; }

 private:
  const Scene& scene_;
  RTCDevice device_ = nullptr;
  RTCScene rtc_scene_ = nullptr;
  float extent_ = 1.0f;
};

}  // namespace exitance
