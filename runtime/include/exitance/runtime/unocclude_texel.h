// The "unocclude" step for one texel: a texel centre that falls inside or behind nearby geometry
// (a floor texel under a wall) is pushed out to the visible side, so corners do not go black. The
// offline stage runs it on every texel with Embree (bake/raster/unocclude.cpp); the runtime runs
// it again near instances an edit moved, on the lighting scene's BVH4 (core/bvh4_closest_hit.h).
#pragma once
#include <functional>

#include "exitance/runtime/texel_gbuffer.h"
#include "exitance/runtime/vec_math.h"

namespace exitance {

// The nearest surface along a ray within reach: its distance and unit geometric normal (from the
// winding: the front side).
struct OccluderHit {
  bool found = false;
  float distance = 0;
  Vec3 geometric_normal;
};
using ClosestHitQuery = std::function<OccluderHit(const Vec3& origin, const Vec3& direction, float t_max)>;

// How far unocclude_texel looks: a texel's half-diagonal, slightly more.
inline float unocclude_reach(const LiveTexel& texel) { return texel.world_texel_size * 0.75f; }

// Casts 8 rays sideways (tilted slightly up) within 0.75 texel of the centre; when the nearest
// surface seen is a back face, moves texel.position just past it, on the texel's own plane.
// Every ray starts at offset_ray_origin(position, geometric_normal) and climbs away from the
// texel's plane (its direction has a positive normal component): bake/raster/unocclude.cpp relies
// on that to skip texels with nothing but their own plane within reach. Returns whether it moved. `scene_extent`: the scale of ray-offset floors (ray_offset.h).
bool unocclude_texel(LiveTexel& texel, float scene_extent, const ClosestHitQuery& closest_hit);

}  // namespace exitance
