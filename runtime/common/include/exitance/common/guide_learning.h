// What grid guiding learns from one continuation ray (issue 11; core/grid_guiding_cache.h has the
// choices), written once for the CPU reference and the Vulkan wavefront so both teach their tables
// the same target in the same fixed-point units.
//
// The target for the bin of direction wi at vertex x, whose ray hits y: L_e(y, -wi) + albedo(y) *
// Lbar(y), luminances, with Lbar(y) the frozen (front) table's cosine-weighted mean at y's record
// (the SARSA bootstrap with its expectation memoized per record). An escaping ray learns the sky;
// a single-sided back face learns 0. The caller looks Lbar up (its cache or buffer): the hit says where.
#ifndef EXITANCE_COMMON_GUIDE_LEARNING_H
#define EXITANCE_COMMON_GUIDE_LEARNING_H
#include "exitance/common/path.h"
EXITANCE_NAMESPACE_BEGIN

struct GuideLearningHit {
  float emitted;            // luminance of L_e(y, -wi) (or of the sky for an escaping ray)
  float albedo;             // luminance of the albedo at y; 0 when nothing is reflected
  bool reads_expectation;   // whether Lbar at y enters the target (a front or double-sided face)
  SurfacePoint y;           // where Lbar is read: the record of (y.position, y.shading_normal)
};

EXITANCE_FN GuideLearningHit guide_learning_escape(SCENE_PARAM vec3 wi) {
  GuideLearningHit h;
  h.emitted = luminance(scene_sky_radiance(SCENE_ARG wi));
  h.albedo = 0.0f;
  h.reads_expectation = false;
  h.y.position = vec3(0.0f);
  h.y.geometric_normal = vec3(0.0f);
  h.y.shading_normal = vec3(0.0f);
  return h;
}

EXITANCE_FN GuideLearningHit guide_learning_hit(SCENE_PARAM uint tri, float b1, float b2, vec3 wi) {
  GuideLearningHit h = guide_learning_escape(SCENE_ARG wi);
  h.emitted = 0.0f;
  vec3 ng = triangle_geometric_normal(SCENE_ARG tri);
  bool front = dot(wi, ng) < 0.0f;
  if (!front && !material_double_sided(scene_material(SCENE_ARG scene_triangle_material(SCENE_ARG tri)))) return h;
  h.y = surface_point_on_triangle(SCENE_ARG tri, ng, b1, b2, front);
  h.emitted = luminance(scene_emission(SCENE_ARG tri, b1, b2));
  h.albedo = luminance(scene_albedo(SCENE_ARG tri, b1, b2));
  h.reads_expectation = true;
  return h;
}

// `expected_cosine`: Lbar at h.y (ignored unless h.reads_expectation).
EXITANCE_FN float guide_learning_target(GuideLearningHit h, float expected_cosine) {
  return h.reads_expectation ? h.emitted + h.albedo * expected_cosine : h.emitted;
}

// A target in the back table's fixed-point units (integer sums do not depend on the order of the
// adds): capped at `cap` radiance, `units` per unit of radiance, rounded. Targets that are not >= 0
// (NaN) are not learned: the caller skips them.
EXITANCE_FN uint64_t guide_fixed_point(float target, float cap, double units) {
  return uint64_t(double(min(target, cap)) * units + 0.5);
}

EXITANCE_NAMESPACE_END
#endif
