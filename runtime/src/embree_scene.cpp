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
