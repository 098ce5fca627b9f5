// Embree 3 BVH over the scene's triangle soup: closest hit and any hit for single rays.
#pragma once
#include <embree3/rtcore.h>

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
  // Closest hit ignoring the triangles of one mesh instance (for scene checks, not lighting).
  Hit intersect_other_instances(Vec3 origin, Vec3 direction, float t_max, uint32_t ignored_instance) const;
  // Largest side of the scene's bounding box: the scale of ray-offset error floors.
  float extent() const { return extent_; }

 private:
  const Scene& scene_;
  RTCDevice device_ = nullptr;
  RTCScene rtc_scene_ = nullptr;
  float extent_ = 1.0f;
};

}  // namespace exitance
