#include "exitance/runtime/embree_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "exitance/runtime/alpha_coverage.h"

namespace exitance {
namespace {

// Intersection context carrying the predicate a filter applies to every hit.
struct PredicateFilterContext {
  RTCIntersectContext context;  // first member: Embree passes a pointer to it
  const Scene* scene;
  const std::function<bool(const Hit&)>* accept;
};

void reject_unless_accepted(const RTCFilterFunctionNArguments* args) {
  const auto* filter = reinterpret_cast<const PredicateFilterContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    Hit hit;
    hit.found = true;
    hit.distance = RTCRayN_tfar(args->ray, args->N, i);  // Embree passes the hit distance as tfar
    hit.triangle = RTCHitN_primID(args->hit, args->N, i);
    hit.b1 = RTCHitN_u(args->hit, args->N, i);
    hit.b2 = RTCHitN_v(args->hit, args->N, i);
    hit.geometric_normal = triangle_normal(*filter->scene, hit.triangle);
    if (!(*filter->accept)(hit)) args->valid[i] = 0;
  }
}

// Geometry filter for MASK and BLEND materials (alpha_coverage.h): a hit where the surface is
// transparent for this ray is rejected, and Embree goes on to the next one.
void reject_transparent_hits(const RTCFilterFunctionNArguments* args) {
  const auto* scene = static_cast<const Scene*>(args->geometryUserPtr);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const uint32_t triangle = RTCHitN_primID(args->hit, args->N, i);
    if (scene->materials[scene->triangle_material[triangle]].alpha_mode == Material::AlphaMode::Opaque) continue;
    const Vec3 origin{RTCRayN_org_x(args->ray, args->N, i), RTCRayN_org_y(args->ray, args->N, i),
                      RTCRayN_org_z(args->ray, args->N, i)};
    const Vec3 direction{RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                         RTCRayN_dir_z(args->ray, args->N, i)};
    const float u = blend_decision_number(origin, direction, triangle);
    if (!hit_is_opaque(*scene, triangle, RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i), u))
      args->valid[i] = 0;
  }
}

Hit make_hit(const Scene& scene, const RTCRayHit& rayhit) {
  Hit hit;
  if (rayhit.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
  hit.found = true;
  hit.distance = rayhit.ray.tfar;
  hit.triangle = rayhit.hit.primID;
  hit.b1 = rayhit.hit.u;
  hit.b2 = rayhit.hit.v;
  // Recomputed from our own vertices so the front side follows glTF's counter-clockwise winding.
  hit.geometric_normal = triangle_normal(scene, hit.triangle);
  return hit;
}

RTCRayHit make_ray(Vec3 origin, Vec3 direction, float t_max) {
  RTCRayHit rayhit{};
  rayhit.ray.org_x = origin.x, rayhit.ray.org_y = origin.y, rayhit.ray.org_z = origin.z;
  rayhit.ray.dir_x = direction.x, rayhit.ray.dir_y = direction.y, rayhit.ray.dir_z = direction.z;
  rayhit.ray.tnear = 0.0f;
  rayhit.ray.tfar = t_max;
  rayhit.ray.mask = 0xFFFFFFFFu;
  rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  return rayhit;
}

// Closest point of triangle (a, b, c) to p: Ericson, Real-Time Collision Detection, 5.1.5 (the
// Voronoi regions of the vertices, then the edges, then the face).
Vec3 closest_point_on_triangle(Vec3 p, Vec3 a, Vec3 b, Vec3 c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const float d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const float d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const float denominator = va + vb + vc;
  if (!(denominator > 0)) return a;  // degenerate triangle: its vertices are as close as it gets
  return a + ab * (vb / denominator) + ac * (vc / denominator);
}

// Point-query callback: shrinks the query radius to the distance of every closer triangle.
bool shrink_to_closer_triangle(RTCPointQueryFunctionArguments* args) {
  const Scene& scene = *static_cast<const Scene*>(args->userPtr);
  const size_t t = args->primID;
  const Vec3 p{args->query->x, args->query->y, args->query->z};
  const Vec3* v = &scene.positions[t * 3];
  const Vec3 q = closest_point_on_triangle(p, v[0], v[1], v[2]);
  const float d = length(q - p);
  if (!(d < args->query->radius)) return false;
  args->query->radius = d;
  return true;
}

// Point-query state for any_triangle_within.
struct RelevantTriangleSearch {
  const Scene* scene;
  const std::function<bool(uint32_t, const Vec3*)>* relevant;
  bool found = false;
};

// Point-query callback: stops the query (radius 0) at the first relevant triangle within the radius.
bool stop_at_relevant_triangle(RTCPointQueryFunctionArguments* args) {
  auto* search = static_cast<RelevantTriangleSearch*>(args->userPtr);
  if (search->found) return false;
  const uint32_t t = args->primID;
  const Vec3 p{args->query->x, args->query->y, args->query->z};
  const Vec3* v = &search->scene->positions[size_t(t) * 3];
  if (!(length(closest_point_on_triangle(p, v[0], v[1], v[2]) - p) <= args->query->radius)) return false;
  if (!(*search->relevant)(t, v)) return false;
  search->found = true;
  args->query->radius = 0;
  return true;
}

// An Embree point query of `radius` around `center`; returns the radius the callback left.
float point_query(RTCScene scene, Vec3 center, float radius, RTCPointQueryFunction callback, void* user) {
  RTCPointQuery query{};
  query.x = center.x, query.y = center.y, query.z = center.z;
  query.time = 0;
  query.radius = radius;
  RTCPointQueryContext context;
  rtcInitPointQueryContext(&context);
  rtcPointQuery(scene, &query, &context, callback, user);
  return query.radius;
}

}  // namespace

EmbreeScene::EmbreeScene(const Scene& scene) : scene_(scene) {
  device_ = new_embree_device();
  rtc_scene_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(rtc_scene_, RTC_BUILD_QUALITY_HIGH);
  rtcSetSceneFlags(rtc_scene_, RTCSceneFlags(RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION));
  RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  const size_t triangles = scene.triangle_count();
  float* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), triangles * 3));
  uint32_t* indices = static_cast<uint32_t*>(
      rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), triangles));
  if (!vertices || !indices) throw std::runtime_error("Embree: out of memory for geometry buffers");
  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (size_t i = 0; i < triangles * 3; ++i) {
    lo = min(lo, scene.positions[i]);
    hi = max(hi, scene.positions[i]);
    vertices[3 * i] = scene.positions[i].x;
    vertices[3 * i + 1] = scene.positions[i].y;
    vertices[3 * i + 2] = scene.positions[i].z;
    indices[i] = uint32_t(i);
  }
  if (triangles > 0) extent_ = std::max(max_component(hi - lo), 1e-30f);
  if (has_alpha_tested_materials(scene)) {
    rtcSetGeometryUserData(geometry, const_cast<Scene*>(&scene_));
    rtcSetGeometryIntersectFilterFunction(geometry, reject_transparent_hits);
    rtcSetGeometryOccludedFilterFunction(geometry, reject_transparent_hits);
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(rtc_scene_, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(rtc_scene_);
  if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw std::runtime_error("Embree: scene build failed");
}

EmbreeScene::~EmbreeScene() {
  if (rtc_scene_) rtcReleaseScene(rtc_scene_);
  if (device_) rtcReleaseDevice(device_);
}

Hit EmbreeScene::intersect(Vec3 origin, Vec3 direction, float t_max) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rayhit = make_ray(origin, direction, t_max);
  rtcIntersect1(rtc_scene_, &context, &rayhit);
  return make_hit(scene_, rayhit);
}

bool EmbreeScene::any_hit_where(Vec3 origin, Vec3 direction, float t_max,
                                const std::function<bool(const Hit&)>& accept) const {
  PredicateFilterContext filter;
  rtcInitIntersectContext(&filter.context);
  filter.context.filter = reject_unless_accepted;
  filter.scene = &scene_;
  filter.accept = &accept;
  RTCRay ray = make_ray(origin, direction, t_max).ray;
  rtcOccluded1(rtc_scene_, &filter.context, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar = -inf once a hit passes the filter
}

float EmbreeScene::distance_to_nearest_triangle(Vec3 point, float max_distance) const {
  const float nearest = point_query(rtc_scene_, point, max_distance, shrink_to_closer_triangle, const_cast<Scene*>(&scene_));
  return nearest < max_distance ? nearest : INFINITY;
}

bool EmbreeScene::any_triangle_within(Vec3 center, float radius,
                                      const std::function<bool(uint32_t, const Vec3*)>& relevant) const {
  RelevantTriangleSearch search{&scene_, &relevant};
  point_query(rtc_scene_, center, radius, stop_at_relevant_triangle, &search);
  return search.found;
}

bool EmbreeScene::occluded(Vec3 origin, Vec3 direction, float t_max) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray{};
  ray.org_x = origin.x, ray.org_y = origin.y, ray.org_z = origin.z;
  ray.dir_x = direction.x, ray.dir_y = direction.y, ray.dir_z = direction.z;
  ray.tnear = 0.0f;
  ray.tfar = t_max;
  ray.mask = 0xFFFFFFFFu;
  rtcOccluded1(rtc_scene_, &context, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
}

}  // namespace exitance
