// One light subpath's walk (light_subpaths.h), shared by the CPU backend's pool (cpu/light_vertex_pool.cpp)
// and the Vulkan backend's (shaders/wavefront/light_subpaths.comp): where it starts, the vertex each
// hit makes, and the continuation. The caller traces the rays (Embree or bvh.glsl) and gives, at the
// first hit, the strategy next-event estimation would use there (emitter guiding's, where learned).
// A walk carries beta, what the path's contribution f has so far over the densities that sampled it
// (in the eye estimator's measure once alpha's cosine is applied at a hit), and the MIS sums.
#ifndef EXITANCE_COMMON_LIGHT_SUBPATH_WALK_H
#define EXITANCE_COMMON_LIGHT_SUBPATH_WALK_H
#include "exitance/common/light_layers.h"
#include "exitance/common/light_subpaths.h"
#include "exitance/common/path.h"
EXITANCE_NAMESPACE_BEGIN

const uint kSubpathFromArea = 0u;      // an emissive triangle
const uint kSubpathFromSky = 1u;       // the sky (at infinity)
const uint kSubpathFromPunctual = 2u;  // a point, spot or directional light (a directional one at infinity)

struct LightSubpathWalk {
  vec3 beta;            // L_e cos / p_start at the start, then alpha x albedo x cos toward the next edge
  vec3 origin;
  vec3 direction;
  float pdf_direction;  // solid-angle density of `direction`; disk_density on a start at infinity's first edge
  float cos_previous;   // |cos| at the previous vertex toward this edge
  vec2 sums;            // (a, b) of the previous vertex
  float ratio;          // the previous vertex's reverse ratio
  float start_probability;  // the start's density (area density on an emitter, the light's probability)
  float nee_area_pdf;   // an emitter start: NEE's area density of it by power (unguided)
  uint depth;           // edges from the light to the next hit
  uint from;            // kSubpathFrom*
  bool infinite;        // y_0 at infinity: y_1's density is disk_density x |cos| (no 1 / d^2)
  bool valid;
  uint triangle;        // an emitter start's triangle, barycentrics
  vec2 barycentrics;
  uint light;           // a punctual start's light
  uint layer;           // the light layer of the start (light_layers.h)
};

EXITANCE_FN LightSubpathWalk light_subpath_walk_none() {
  LightSubpathWalk w;
  w.beta = vec3(0.0f);
  w.origin = vec3(0.0f);
  w.direction = vec3(0.0f, 0.0f, 1.0f);
  w.pdf_direction = 0.0f;
  w.cos_previous = 0.0f;
  w.sums = vec2(0.0f, 0.0f);
  w.ratio = 0.0f;
  w.start_probability = 0.0f;
  w.nee_area_pdf = 0.0f;
  w.depth = 1u;
  w.from = kSubpathFromArea;
  w.infinite = false;
  w.valid = false;
  w.triangle = 0u;
  w.barycentrics = vec2(0.0f, 0.0f);
  w.light = 0u;
  w.layer = 0u;
  return w;
}

// A start at infinity travelling along `direction`: a point uniform on the disc of the bounds' sphere
// (centre, radius) across it, outside the sphere.
EXITANCE_FN void light_subpath_enter_from_infinity(INOUT(LightSubpathWalk) w, vec3 direction, vec3 centre, float radius,
                                                   float disk_density, INOUT(PathSampler) rng) {
  vec2 u = sample_2d(rng);
  float r = radius * sqrt(u.x);
  float phi = 2.0f * kPi * u.y;
  w.origin = centre - direction * radius + to_world(vec3(r * cos(phi), r * sin(phi), 0.0f), direction);
  w.direction = direction;
  w.pdf_direction = disk_density;
  w.infinite = true;
}

EXITANCE_FN LightSubpathWalk light_subpath_start_on_emitter(SCENE_PARAM LightSubpathSampling start, float u_choose,
                                                            INOUT(PathSampler) rng) {
  LightSubpathWalk w = light_subpath_walk_none();
  vec2 u = sample_2d(rng);
  EmitterPoint point = emitter_mixture_sample(scene_emitter_cdf(SCENE_ALONE_ARG), scene_emitter_count(SCENE_ALONE_ARG),
                                              emitter_guide_none(), u_choose, u.x, u.y);
  uint tri = scene_emitter_triangle(SCENE_ARG point.emitter);
  vec3 p0 = scene_triangle_vertex(SCENE_ARG tri, 0u);
  vec3 p1 = scene_triangle_vertex(SCENE_ARG tri, 1u);
  vec3 p2 = scene_triangle_vertex(SCENE_ARG tri, 2u);
  vec2 b = point.barycentrics;
  vec3 position = p0 * (1.0f - b.x - b.y) + p1 * b.x + p2 * b.y;
  vec3 ng = normalize(cross(p1 - p0, p2 - p0));
  GpuMaterial m = scene_material(SCENE_ARG scene_triangle_material(SCENE_ARG tri));
  bool double_sided = material_double_sided(m);
  vec3 n = ng;
  if (double_sided && sample_1d(rng) < 0.5f) n = -ng;
  vec2 ud = sample_2d(rng);
  vec3 local = sample_cosine_hemisphere(ud.x, ud.y);
  if (!(local.z > 0.0f)) return w;
  w.nee_area_pdf = scene_triangle_area_pdf(SCENE_ARG tri);
  float p_start = start.area_probability * w.nee_area_pdf;
  if (!(p_start > 0.0f)) return w;
  w.valid = true;
  w.from = kSubpathFromArea;
  w.direction = to_world(local, n);
  w.cos_previous = local.z;
  w.pdf_direction = emitter_direction_pdf(local.z, double_sided);
  w.beta = scene_emission(SCENE_ARG tri, b.x, b.y) * (local.z / p_start);
  w.origin = offset_ray_origin(position, n, scene_extent(SCENE_ALONE_ARG));
  w.start_probability = p_start;
  w.triangle = tri;
  w.barycentrics = b;
  w.layer = uint(m.emission.w);
  return w;
}

EXITANCE_FN LightSubpathWalk light_subpath_start_in_sky(SCENE_PARAM LightSubpathSampling start, vec3 centre, float radius,
                                                        INOUT(PathSampler) rng) {
  LightSubpathWalk w = light_subpath_walk_none();
  vec2 u = sample_2d(rng);
  float pdf = constant_sky_direction_pdf();
  vec3 toward_sky;
  if (scene_has_environment(SCENE_ALONE_ARG)) {
    toward_sky = scene_sample_environment(SCENE_ARG u.x, u.y, pdf);
  } else {
    toward_sky = uniform_sphere(u.x, u.y);
  }
  float p_start = start.sky_probability * pdf;
  vec3 radiance = scene_sky_radiance(SCENE_ARG toward_sky);
  if (!(p_start > 0.0f) || !(max_component(radiance) > 0.0f)) return w;
  light_subpath_enter_from_infinity(w, -toward_sky, centre, radius, start.disk_density, rng);
  w.valid = true;
  w.from = kSubpathFromSky;
  w.beta = radiance / p_start;
  w.start_probability = p_start;
  w.layer = kSkyLightLayer;
  return w;
}

EXITANCE_FN LightSubpathWalk light_subpath_start_at_punctual(SCENE_PARAM LightSubpathSampling start, vec3 centre, float radius,
                                                             uint punctual_layers, float u_choose, INOUT(PathSampler) rng) {
  LightSubpathWalk w = light_subpath_walk_none();
  float pmf;
  uint index = sample_cdf(scene_punctual_cdf(SCENE_ALONE_ARG), scene_punctual_count(SCENE_ALONE_ARG), u_choose, pmf);
  GpuPunctualLight light = scene_punctual_light(SCENE_ARG index);
  float p_start = start.punctual_scale * pmf;
  vec3 axis = vec3(light.direction_cos_inner.x, light.direction_cos_inner.y, light.direction_cos_inner.z);
  vec3 intensity = vec3(light.intensity_cos_outer.x, light.intensity_cos_outer.y, light.intensity_cos_outer.z);
  w.from = kSubpathFromPunctual;
  w.light = index;
  w.layer = punctual_light_layer(index, punctual_layers);
  w.start_probability = p_start;
  if (floatBitsToUint(light.position_type.w) == kPunctualDirectional) {
    if (!(p_start > 0.0f)) return w;
    light_subpath_enter_from_infinity(w, axis, centre, radius, start.disk_density, rng);
    w.valid = true;
    w.beta = intensity / p_start;
    return w;
  }
  vec2 u = sample_2d(rng);
  bool spot = floatBitsToUint(light.position_type.w) == kPunctualSpot;
  vec3 direction = spot ? sample_spot_cone(axis, light.intensity_cos_outer.w, u.x, u.y) : uniform_sphere(u.x, u.y);
  w.pdf_direction = punctual_direction_pdf(light, direction);
  if (!(w.pdf_direction > 0.0f) || !(p_start > 0.0f)) return w;
  float attenuation = spot ? spot_attenuation(axis, light.direction_cos_inner.w, light.intensity_cos_outer.w, direction) : 1.0f;
  if (!(attenuation > 0.0f)) return w;
  w.valid = true;
  w.direction = direction;
  w.beta = intensity * (attenuation / p_start);
  w.origin = vec3(light.position_type.x, light.position_type.y, light.position_type.z);
  return w;
}

// A subpath's start: on an emitter, in the sky or at a punctual light, by the probabilities `start`
// holds (light_subpath_start on the host). `centre`, `radius`: the bounds' sphere.
EXITANCE_FN LightSubpathWalk light_subpath_begin(SCENE_PARAM LightSubpathSampling start, vec3 centre, float radius,
                                                 uint punctual_layers, INOUT(PathSampler) rng) {
  float u = sample_1d(rng);
  float sky_end = start.area_probability + start.sky_probability;
  bool sky = start.sky_probability > 0.0f && u >= start.area_probability && (u < sky_end || !(start.punctual_scale > 0.0f));
  if (u < start.area_probability) return light_subpath_start_on_emitter(SCENE_ARG start, rescaled_unit(u, 0.0f, start.area_probability), rng);
  if (sky) return light_subpath_start_in_sky(SCENE_ARG start, centre, radius, rng);
  return light_subpath_start_at_punctual(SCENE_ARG start, centre, radius, punctual_layers,
                                         rescaled_unit(u, sky_end, 1.0f - sky_end), rng);
}

// The surface point of the walk's hit on `tri`; false where a single-sided back face absorbs it.
EXITANCE_FN bool light_subpath_surface(SCENE_PARAM LightSubpathWalk w, uint tri, float b1, float b2, OUT(SurfacePoint) y) {
  bool double_sided = material_double_sided(scene_material(SCENE_ARG scene_triangle_material(SCENE_ARG tri)));
  vec3 ng = triangle_geometric_normal(SCENE_ARG tri);
  bool front = dot(w.direction, ng) < 0.0f;
  y = surface_point_on_triangle(SCENE_ARG tri, ng, b1, b2, front);
  return front || double_sided;
}

// Next-event estimation's density of the walk's start from its first hit y, with the strategy `g`
// it uses there; for a constant sky, which NEE does not sample, the eye's escape density toward it.
EXITANCE_FN float light_subpath_nee_density(SCENE_PARAM LightSubpathWalk w, SurfacePoint y, EmitterGuide g) {
  if (w.from == kSubpathFromSky) {
    vec3 toward_sky = -w.direction;
    if (scene_has_environment(SCENE_ALONE_ARG)) return scene_environment_pdf(SCENE_ARG toward_sky);
    return max(dot(y.shading_normal, toward_sky), 0.0f) * kInvPi;
  }
  if (w.from == kSubpathFromArea)
    return w.nee_area_pdf * emitter_guide_ratio_at_triangle(scene_emitter_cdf(SCENE_ALONE_ARG), g, w.triangle, w.barycentrics.x,
                                                            w.barycentrics.y);
  return punctual_mixture_probability(scene_punctual_cdf(SCENE_ALONE_ARG), g, w.light);
}

// The vertex the walk's hit makes (at y, distance t_hit; `nee`: light_subpath_nee_density at the
// first hit, unused deeper), and the hit's albedo. False: the walk ends here without a vertex.
EXITANCE_FN bool light_subpath_vertex(SCENE_PARAM LightSubpathWalk w, uint tri, float t_hit, float b1, float b2, SurfacePoint y,
                                      float nee, OUT(LightVertex) v, OUT(vec3) albedo) {
  vec3 ng = triangle_geometric_normal(SCENE_ARG tri);
  float cos_geometric = abs(dot(ng, w.direction));
  float cos_shading = -dot(y.shading_normal, w.direction);
  bool first_from_infinity = w.depth == 1u && w.infinite;
  float distance2 = first_from_infinity ? 1.0f : t_hit * t_hit;
  albedo = vec3(0.0f);
  if (!(cos_shading > 0.0f) || !(cos_geometric > 0.0f) || !(distance2 > 0.0f)) return false;
  float reverse_density = w.pdf_direction * cos_geometric / distance2;
  vec3 alpha = w.beta * (cos_shading * kInvPi / (w.pdf_direction * cos_geometric));
  // The eye's area density of the previous vertex, sampled (cosine) here (a solid-angle density
  // toward a start at infinity).
  float eye_density = cos_shading * kInvPi * (first_from_infinity ? 1.0f : w.cos_previous / distance2);
  vec2 next_sums;
  float next_ratio;
  if (w.depth == 1u) {
    if (!(nee > 0.0f)) return false;  // NEE samples every light a subpath starts from
    // y_0 hit by the eye against NEE (an emitter, an environment map; a constant sky's NEE is that hit).
    bool hit_by_eye = w.from == kSubpathFromArea || (w.from == kSubpathFromSky && scene_has_environment(SCENE_ALONE_ARG));
    float r0 = hit_by_eye ? eye_density / nee : 0.0f;
    next_sums = vec2(1.0f + r0 * r0, 0.0f);
    next_ratio = nee / w.start_probability / reverse_density;  // e_1 / p_1
  } else {
    next_sums = next_light_sums(w.depth - 1u, w.sums, eye_density * w.ratio);
    next_ratio = 1.0f / reverse_density;
  }
  albedo = scene_albedo(SCENE_ARG tri, b1, b2);
  if (!(max_component(albedo) > 0.0f)) return false;
  vec3 weight = alpha * albedo;
  v.position_depth = vec4(y.position.x, y.position.y, y.position.z, uintBitsToFloat(w.depth));
  v.geometric_normal_layer = vec4(y.geometric_normal.x, y.geometric_normal.y, y.geometric_normal.z, uintBitsToFloat(w.layer));
  v.shading_normal_ratio = vec4(y.shading_normal.x, y.shading_normal.y, y.shading_normal.z, next_ratio);
  v.weight_a = vec4(weight.x, weight.y, weight.z, next_sums.x);
  v.b = vec4(next_sums.y, 0.0f, 0.0f, 0.0f);
  return true;
}

// Whether a vertex is kept in the pool (every number finite).
EXITANCE_FN bool light_vertex_finite(LightVertex v) {
  return !isinf(v.weight_a.x) && !isnan(v.weight_a.x) && !isinf(v.weight_a.y) && !isnan(v.weight_a.y) && !isinf(v.weight_a.z) &&
         !isnan(v.weight_a.z) && !isinf(v.shading_normal_ratio.w) && !isnan(v.shading_normal_ratio.w) && !isinf(v.weight_a.w) &&
         !isnan(v.weight_a.w) && !isinf(v.b.x) && !isnan(v.b.x);
}

// Past vertex v (at y, the hit's albedo): Russian roulette from depth rr_start, then a cosine
// direction; false where the walk ends (max_depth reached, roulette, no direction).
EXITANCE_FN bool light_subpath_continue(SCENE_PARAM INOUT(LightSubpathWalk) w, LightVertex v, SurfacePoint y, vec3 albedo,
                                        int max_depth, int rr_start, INOUT(PathSampler) rng) {
  if (int(w.depth) >= max_depth) return false;
  vec3 carried = vec3(v.weight_a.x, v.weight_a.y, v.weight_a.z);
  if (int(w.depth) >= rr_start) {
    float survive = min(1.0f, max_component(albedo));
    if (sample_1d(rng) >= survive) return false;
    carried = carried / survive;
  }
  DirectionSample d = sample_continuation(kStrategyCosine, y, rng);
  if (!(d.pdf > 0.0f)) return false;
  w.cos_previous = abs(dot(y.geometric_normal, d.direction));
  w.beta = carried * w.cos_previous;
  w.pdf_direction = d.pdf;
  w.origin = offset_ray_origin(y.position, y.geometric_normal, scene_extent(SCENE_ALONE_ARG));
  w.direction = d.direction;
  w.sums = vec2(v.weight_a.w, v.b.x);
  w.ratio = v.shading_normal_ratio.w;
  w.depth += 1u;
  return true;
}

// ---- The eye's side: a connection to a pool vertex ----
// Eye vertex x (bounce `bounce`, light-subpath state `eye`, continuation strategy g, shadow-ray
// origin `origin`, path throughput) connected to pool vertex y (`max_depth`: the deepest vertex
// the pool keeps): the shadow ray toward y and, when unoccluded, its contribution (weighted and
// scaled by 1 / n_c) to E/pi at bounce + y's depth and to y's light layer. No ray (kShadowNone) where
// the connection cannot carry light.
EXITANCE_FN ShadowRay light_subpath_connection(SCENE_PARAM LightSubpathSampling s, LightVertex y, SurfacePoint x, vec3 origin,
                                               vec3 throughput, GuideVertex g, int bounce, EyeSubpathVertex eye, int max_depth) {
  ShadowRay ray = no_shadow_ray();
  uint depth = floatBitsToUint(y.position_depth.w);
  if (bounce + int(depth) > max_depth) return ray;
  vec3 position = vec3(y.position_depth.x, y.position_depth.y, y.position_depth.z);
  vec3 to_light = position - x.position;
  float distance2 = dot(to_light, to_light);
  if (!(distance2 > 0.0f)) return ray;
  vec3 wi = to_light / sqrt(distance2);
  float cos_x = dot(x.shading_normal, wi);
  float cos_x_geometric = dot(x.geometric_normal, wi);
  vec3 y_normal = vec3(y.geometric_normal_layer.x, y.geometric_normal_layer.y, y.geometric_normal_layer.z);
  float cos_y = -dot(y_normal, wi);
  if (!(cos_x > 0.0f) || !(cos_x_geometric > 0.0f) || !(cos_y > 0.0f)) return ray;
  vec3 y_shading = vec3(y.shading_normal_ratio.x, y.shading_normal_ratio.y, y.shading_normal_ratio.z);
  float eye_density = continuation_pdf(g, x, wi) * cos_y / distance2;
  float light_density = max(-dot(y_shading, wi), 0.0f) * kInvPi * cos_x_geometric / distance2;
  float eye_ratio = bounce > 0 && eye.pdf_forward > 0.0f ? light_density / eye.pdf_forward : 0.0f;
  float weight = connection_weight(s, y, eye_density, eye_ratio, eye.eye_sum);
  vec3 c = throughput * vec3(y.weight_a.x, y.weight_a.y, y.weight_a.z) * (cos_x * kInvPi * cos_y / distance2 * s.scale * weight);
  if (!(max_component(c) > 0.0f)) return ray;
  vec3 target = offset_ray_origin(position, y_normal, scene_extent(SCENE_ALONE_ARG));
  vec3 span = target - origin;
  float span_length = length(span);
  if (!(span_length > 0.0f)) return ray;
  ray.direction_length = vec4(span.x / span_length, span.y / span_length, span.z / span_length, span_length);
  ray.contribution_state = vec4(c.x, c.y, c.z, kShadowTrace);
  return ray;
}

EXITANCE_NAMESPACE_END
#endif
