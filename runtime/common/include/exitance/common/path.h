// The path tracer's per-vertex steps, written once for the CPU reference (runtime/src/cpu) and the
// Vulkan wavefront (shaders/wavefront): next-event estimation, the continuation direction (the
// sampling-strategy hook), and what a continuation ray's hit adds and where the path goes next.
// Each backend only traces the rays these functions ask for, so both compute the same estimator,
// and the same (seed, item, sample) gives the same path on both up to floating-point rounding.
//
// The estimator, per lightmap texel (E/pi): cosine-weighted (or guided) continuation rays; next-event
// estimation to emissive triangles (picked by power, uniform by area), punctual lights (by power) and
// the environment map; power-heuristic MIS between the continuation and the area/environment samples;
// back faces of single-sided surfaces absorb; Russian roulette from bounce rr_start.
//
// Scene data comes through accessors the including code defines first (C++: scene_access.h over a
// LightingScene; GLSL: shaders/include/scene_access.glsl over the descriptor set):
//   vec3 scene_triangle_vertex(SCENE_PARAM uint t, uint k), vec3 scene_triangle_normal(SCENE_PARAM uint t, uint k),
//   uint scene_triangle_material(SCENE_PARAM uint t), float scene_triangle_area_pdf(SCENE_PARAM uint t)
//   GpuMaterial scene_material(SCENE_PARAM uint m)
//   GpuPunctualLight scene_punctual_light(SCENE_PARAM uint i)
//   uint scene_emitter_count(SCENE_ALONE_PARAM)           uint scene_emitter_triangle(SCENE_PARAM uint i)
//   uint scene_punctual_count(SCENE_ALONE_PARAM)          float scene_extent(SCENE_ALONE_PARAM)
//   CDF references scene_emitter_cdf(SCENE_ALONE_PARAM), scene_punctual_cdf(SCENE_ALONE_PARAM)
//   vec3 scene_albedo(SCENE_PARAM uint t, float b1, float b2), vec3 scene_emission(SCENE_PARAM uint t, float b1, float b2)
//   vec3 scene_sky_radiance(SCENE_PARAM vec3 direction)
//   bool scene_has_environment(SCENE_ALONE_PARAM), float scene_environment_pdf(SCENE_PARAM vec3 direction),
//   vec3 scene_sample_environment(SCENE_PARAM float u1, float u2, OUT(float) pdf)
#ifndef EXITANCE_COMMON_PATH_H
#define EXITANCE_COMMON_PATH_H
#include "exitance/common/distribution.h"
#include "exitance/common/gpu_layout.h"
#include "exitance/common/guided_direction.h"
#include "exitance/common/guided_emitters.h"
#include "exitance/common/light_subpaths.h"
#include "exitance/common/punctual_light.h"
#include "exitance/common/ray_offset.h"
#include "exitance/common/path_sampler.h"
#include "exitance/common/sampling.h"
EXITANCE_NAMESPACE_BEGIN

struct SurfacePoint {
  vec3 position;
  vec3 geometric_normal;  // unit, on the side the path arrived from
  vec3 shading_normal;    // unit, same hemisphere as geometric_normal
};

struct PathLimits {
  int max_bounces;  // diffuse bounces after the first hit; -1 = until Russian roulette
  int rr_start;     // first bounce at which roulette may end a path
  int safety_cap;   // bounces never exceeded whatever roulette says
};

// ---- Sampling-strategy hook: the continuation direction at a surface vertex ----
// kStrategyCosine: cosine-weighted. A guided vertex (GuideVertex, guided_direction.h) samples the
// one-sample mixture m * guided + (1 - m) * cosine, and its pdf is the mixture's: next-event
// estimation weighs its samples with continuation_pdf, so its MIS stays right for any strategy.
const uint kStrategyCosine = 0u;

struct DirectionSample {
  vec3 direction;
  float pdf;  // solid-angle density; 0: no usable direction, the path ends
};

EXITANCE_FN GuideVertex guide_vertex_cosine() {
  GuideVertex g;
  g.guided_probability = 0.0f;
  g.normal_class = 0u;
  g.cdf = GUIDE_CDF_NONE;
  g.uniform_probability = 0.0f;
  return g;
}

// Directional (L1 SH) bakes sample a texel's FIRST continuation from the defensive mixture
// (1 - kDirectionalUniformProbability) * strategy + kDirectionalUniformProbability * uniform hemisphere:
// the L1 estimate c * w / (2 cos) of a contribution c = L cos / (pi p) is then bounded by
// L / (2 * kDirectionalUniformProbability), where pure cosine sampling has infinite variance at
// grazing angles (docs/bundle.md, "Directional layers").
const float kDirectionalUniformProbability = 0.25f;

EXITANCE_FN GuideVertex with_uniform_component(GuideVertex g, float probability) {
  g.uniform_probability = probability;
  return g;
}

// The pdf of the vertex's strategy without the defensive component.
EXITANCE_FN float strategy_pdf(GuideVertex g, SurfacePoint x, vec3 wi) {
  float cosine = max(dot(x.shading_normal, wi), 0.0f) * kInvPi;
  if (!(g.guided_probability > 0.0f)) return cosine;
  return g.guided_probability * guided_component_pdf(g, wi) + (1.0f - g.guided_probability) * cosine;
}

// A vertex with guided_probability 0 and uniform_probability 0 computes exactly what the cosine
// strategy computes.
EXITANCE_FN float continuation_pdf(GuideVertex g, SurfacePoint x, vec3 wi) {
  if (!(g.uniform_probability > 0.0f)) return strategy_pdf(g, x, wi);
  float uniform_pdf = dot(x.shading_normal, wi) > 0.0f ? 0.5f * kInvPi : 0.0f;
  return (1.0f - g.uniform_probability) * strategy_pdf(g, x, wi) + g.uniform_probability * uniform_pdf;
}

EXITANCE_FN float continuation_pdf(uint strategy, SurfacePoint x, vec3 wi) {
  return continuation_pdf(guide_vertex_cosine(), x, wi);
}

// Draws one 2-D sample. A direction under the geometric surface would leave through the back: none.
EXITANCE_FN DirectionSample sample_continuation(uint strategy, SurfacePoint x, INOUT(PathSampler) rng) {
  vec2 u = sample_2d(rng);
  vec3 local = sample_cosine_hemisphere(u.x, u.y);
  DirectionSample s;
  s.direction = to_world(local, x.shading_normal);
  s.pdf = local.z * kInvPi;
  if (!(dot(s.direction, x.geometric_normal) > 0.0f) || local.z <= 0.0f) s.pdf = 0.0f;
  return s;
}

// Cosine vertices: as above. Guided (or defensive) vertices spend the same 2-D sample (u1, u2) as
// cosine ones, so a guided texel keeps the Sobol sampler's 2-D stratification of its first bounce
// (drawing the component choice and the in-bin point from extra dimensions cost guided texels up to
// 1.6x the relMSE per sample: bench/results/guiding-svo.md). u1 picks the component: below
// uniform_probability the defensive uniform component, then the guided one with probability
// guided_probability, else cosine; u1 rescaled into the chosen interval is that component's first
// number (guided: the bin by CDF inversion, then its remainder inside the bin's CDF interval places
// the point across the bin), u2 its second. A direction under the surface (shading or geometric)
// ends the path: the integrand is 0 there.
EXITANCE_FN DirectionSample sample_continuation(GuideVertex g, SurfacePoint x, INOUT(PathSampler) rng) {
  if (!(g.guided_probability > 0.0f) && !(g.uniform_probability > 0.0f))
    return sample_continuation(kStrategyCosine, x, rng);
  vec2 u = sample_2d(rng);
  DirectionSample s;
  if (u.x < g.uniform_probability) {
    s.direction = to_world(sample_uniform_hemisphere(rescaled_unit(u.x, 0.0f, g.uniform_probability), u.y), x.shading_normal);
  } else {
    float u_strategy = rescaled_unit(u.x, g.uniform_probability, 1.0f - g.uniform_probability);
    if (u_strategy < g.guided_probability) {
      s.direction = guided_component_sample(g, rescaled_unit(u_strategy, 0.0f, g.guided_probability), u.y);
    } else {
      float u_cosine = rescaled_unit(u_strategy, g.guided_probability, 1.0f - g.guided_probability);
      s.direction = to_world(sample_cosine_hemisphere(u_cosine, u.y), x.shading_normal);
    }
  }
  s.pdf = continuation_pdf(g, x, s.direction);
  if (!(dot(s.direction, x.geometric_normal) > 0.0f) || !(dot(s.direction, x.shading_normal) > 0.0f)) s.pdf = 0.0f;
  return s;
}

// The factor (cos / pi) / pdf the continuation carries into the path's throughput (the albedo is
// applied at the hit): exactly 1 for cosine vertices, so unguided results do not change.
EXITANCE_FN float continuation_weight(GuideVertex g, SurfacePoint x, DirectionSample d) {
  if (!(g.guided_probability > 0.0f) && !(g.uniform_probability > 0.0f)) return 1.0f;
  return max(dot(x.shading_normal, d.direction), 0.0f) * kInvPi / d.pdf;
}

// ---- Directional (L1 SH) texels ----
// A contribution c to a texel's E/pi whose path left the texel in direction w (the shadow ray's for
// next-event samples at the texel, the first continuation's for everything else) adds
// c[channel] * f[axis] to L1[axis][channel], f = w / (2 cos), cos = dot(shading normal, w): since
// c = L cos / (pi p), that is L w / (2 pi p), an unbiased estimate of (1 / 2 pi) * integral of L w.
// 0 for directions at or under the shading horizon (c is 0 there too).
EXITANCE_FN vec3 sh1_direction_factor(SurfacePoint x, vec3 w) {
  float cosine = dot(x.shading_normal, w);
  if (!(cosine > 0.0f)) return vec3(0.0f);
  return w * (0.5f / cosine);
}

// ---- Next-event estimation ----
EXITANCE_FN ShadowRay no_shadow_ray() {
  ShadowRay r;
  r.direction_length = vec4(0.0f, 0.0f, 0.0f, 0.0f);
  r.contribution_state = vec4(0.0f, 0.0f, 0.0f, kShadowNone);
  return r;
}

// Triangle data is read field by field (scene_triangle_vertex and friends), so each step names what
// it loads (on the H200 this measured the same as whole-record copies).
EXITANCE_FN vec3 triangle_geometric_normal(SCENE_PARAM uint tri) {
  vec3 p0 = scene_triangle_vertex(SCENE_ARG tri, 0u);
  return normalize(cross(scene_triangle_vertex(SCENE_ARG tri, 1u) - p0, scene_triangle_vertex(SCENE_ARG tri, 2u) - p0));
}
EXITANCE_FN bool material_double_sided(GpuMaterial m) { return m.albedo_double_sided.w != 0.0f; }

// Punctual light `light`'s direct E/pi at x, chosen with `probability`: its shadow ray, carrying
// throughput * I falloff cos / (pi probability) when unoccluded (no ray where the light cannot reach
// x). Returns luminance(I falloff cos / pi) / probability, what emitter guiding learns.
EXITANCE_FN float punctual_light_ray(GpuPunctualLight light, SurfacePoint x, vec3 throughput, float probability,
                                     OUT(ShadowRay) ray) {
  ray = no_shadow_ray();
  uint type = floatBitsToUint(light.position_type.w);
  vec3 direction = vec3(light.direction_cos_inner.x, light.direction_cos_inner.y, light.direction_cos_inner.z);
  vec3 wi;
  float distance = uintBitsToFloat(0x7F800000u);
  float falloff = 1.0f;
  if (type == kPunctualDirectional) {
    wi = -direction;
  } else {
    vec3 to_light = vec3(light.position_type.x, light.position_type.y, light.position_type.z) - x.position;
    distance = length(to_light);
    wi = to_light / distance;
    falloff = 1.0f / (distance * distance);
    if (type == kPunctualSpot)
      falloff *= spot_attenuation(direction, light.direction_cos_inner.w, light.intensity_cos_outer.w, -wi);
  }
  float cos_x = dot(x.shading_normal, wi);
  if (!(distance > 0.0f && falloff > 0.0f && cos_x > 0.0f && dot(x.geometric_normal, wi) > 0.0f && probability > 0.0f)) return 0.0f;
  vec3 intensity = vec3(light.intensity_cos_outer.x, light.intensity_cos_outer.y, light.intensity_cos_outer.z);
  ray.direction_length = vec4(wi, distance);
  ray.contribution_state = vec4(throughput * (intensity * (falloff * cos_x * kInvPi / probability)), kShadowTrace);
  return luminance(intensity) * falloff * cos_x * kInvPi / probability;
}

// One sample of each light strategy at x: (1/pi) * integral of direct radiance * cos, as shadow rays.
// Random numbers, in order: area light (choice, then a 2-D point), punctual light (choice),
// environment (a 2-D direction);
// each only when the scene has lights of that kind.
// Three named outputs (area light, punctual light, environment) rather than an array.
// `guide`: the vertex's continuation strategy, whose pdf weighs the area and environment samples.
// `emitter_guide` (guided_emitters.h): the vertex's learned area-light strategy; with tables but
// guided_probability 0 it samples by default and still reports the patch, for learning.
// `learning`: the area sample's patch (kEmitterPatchNone: no tables or no sample) and its value
// luminance(L_e) cos / (pi p), unweighted by MIS and throughput, which counts when the ray is unoccluded.
struct EmitterLearning {
  uint patch_index;
  float value;
  uint punctual_light;  // kEmitterPatchNone: no punctual tables or no sample
  float punctual_value; // luminance(I falloff cos / pi) / probability
  // Where the shadow rays' light comes from (light layers, light_layers.h), whether guided or not:
  // the area sample's triangle and the punctual light chosen (kEmitterPatchNone: no sample).
  uint area_triangle;
  uint punctual_index;
};

// An eye vertex's light-subpath state (light_subpaths.h), which its next-event and emitter-hit weights
// need: sampling.count 0 (no pool) gives the path tracer's weights.
struct EyeSubpathVertex {
  LightSubpathSampling sampling;
  float pdf_forward;  // the eye's area density of this vertex; 0 at the texel (never moved)
  float eye_sum;      // C_j
};

EXITANCE_FN EyeSubpathVertex eye_subpath_vertex_none() {
  EyeSubpathVertex e;
  e.sampling = light_subpaths_none();
  e.pdf_forward = 0.0f;
  e.eye_sum = 1.0f;
  return e;
}

EXITANCE_FN void next_event_estimation(SCENE_PARAM SurfacePoint x, vec3 origin, vec3 throughput, GuideVertex guide,
                                       EmitterGuide emitter_guide, EyeSubpathVertex eye, INOUT(PathSampler) rng,
                                       OUT(ShadowRay) area_ray, OUT(ShadowRay) punctual_ray,
                                       OUT(ShadowRay) environment_ray, OUT(EmitterLearning) learning) {
  area_ray = no_shadow_ray();
  punctual_ray = no_shadow_ray();
  environment_ray = no_shadow_ray();
  learning.patch_index = kEmitterPatchNone;
  learning.value = 0.0f;
  learning.punctual_light = kEmitterPatchNone;
  learning.punctual_value = 0.0f;
  learning.area_triangle = kEmitterPatchNone;
  learning.punctual_index = kEmitterPatchNone;
  uint emitters = scene_emitter_count(SCENE_ALONE_ARG);
  if (emitters > 0u) {
    float u_choose = sample_1d(rng);
    vec2 u = sample_2d(rng);
    EmitterPoint point = emitter_mixture_sample(scene_emitter_cdf(SCENE_ALONE_ARG), emitters, emitter_guide, u_choose, u.x, u.y);
    vec2 bary = point.barycentrics;
    uint patch_index = point.patch_index;
    uint tri = scene_emitter_triangle(SCENE_ARG point.emitter);
    learning.area_triangle = tri;
    vec3 p0 = scene_triangle_vertex(SCENE_ARG tri, 0u);
    vec3 p1 = scene_triangle_vertex(SCENE_ARG tri, 1u);
    vec3 p2 = scene_triangle_vertex(SCENE_ARG tri, 2u);
    vec3 light_position = p0 * (1.0f - bary.x - bary.y) + p1 * bary.x + p2 * bary.y;
    vec3 light_normal = normalize(cross(p1 - p0, p2 - p0));
    float pdf_area = scene_triangle_area_pdf(SCENE_ARG tri);
    if (patch_index != kEmitterPatchNone)
      pdf_area *= emitter_guide_ratio(scene_emitter_cdf(SCENE_ALONE_ARG), emitter_guide, patch_index);
    vec3 to_light = light_position - x.position;
    float distance2 = dot(to_light, to_light);
    float distance = sqrt(distance2);
    if (distance > 0.0f) {
      vec3 wi = to_light / distance;
      float cos_x = dot(x.shading_normal, wi);
      float cos_l = -dot(light_normal, wi);
      if (material_double_sided(scene_material(SCENE_ARG scene_triangle_material(SCENE_ARG tri)))) cos_l = abs(cos_l);
      if (cos_x > 0.0f && dot(x.geometric_normal, wi) > 0.0f && cos_l > 0.0f) {
        vec3 toward_x = dot(light_normal, wi) < 0.0f ? light_normal : -light_normal;
        vec3 target = offset_ray_origin(light_position, toward_x, scene_extent(SCENE_ALONE_ARG));
        vec3 span = target - origin;
        float span_length = length(span);
        if (span_length > 0.0f) {
          float pdf_light = pdf_area * distance2 / cos_l;
          float weight;
          if (eye.sampling.count > 0.0f) {
            bool double_sided = material_double_sided(scene_material(SCENE_ARG scene_triangle_material(SCENE_ARG tri)));
            float start = light_start_ratio(eye.sampling, eye.sampling.area_probability * scene_triangle_area_pdf(SCENE_ARG tri) / pdf_area,
                                            emitter_direction_pdf(cos_l, double_sided), dot(x.geometric_normal, wi),
                                            distance2, eye.pdf_forward);
            weight = light_subpath_nee_weight(continuation_pdf(guide, x, wi) / pdf_light, start, eye.eye_sum);
          } else {
            weight = power_heuristic(pdf_light, continuation_pdf(guide, x, wi));
          }
          vec3 le = scene_emission(SCENE_ARG tri, bary.x, bary.y);
          area_ray.direction_length = vec4(span / span_length, span_length);
          area_ray.contribution_state = vec4(throughput * (le * (cos_x * kInvPi * weight / pdf_light)), kShadowTrace);
          learning.patch_index = patch_index;
          learning.value = luminance(le) * cos_x * kInvPi / pdf_light;
        } else {
          area_ray.contribution_state = vec4(0.0f, 0.0f, 0.0f, kShadowCountOnly);
        }
      }
    }
  }
  uint punctual = scene_punctual_count(SCENE_ALONE_ARG);
  if (punctual > 0u) {
    float u_choose = sample_1d(rng);
    float probability;
    uint light_index = punctual_mixture_sample(scene_punctual_cdf(SCENE_ALONE_ARG), punctual, emitter_guide, u_choose, probability);
    learning.punctual_index = light_index;
    GpuPunctualLight light = scene_punctual_light(SCENE_ARG light_index);
    float value = punctual_light_ray(light, x, throughput, probability, punctual_ray);
    if (eye.sampling.count > 0.0f && punctual_ray.contribution_state.w == kShadowTrace) {
      vec3 wi = vec3(punctual_ray.direction_length.x, punctual_ray.direction_length.y, punctual_ray.direction_length.z);
      float distance = punctual_ray.direction_length.w;
      float start_over_nee = eye.sampling.punctual_scale * cdf_pmf(scene_punctual_cdf(SCENE_ALONE_ARG), light_index) / probability;
      float start_area = punctual_start_area_factor(eye.sampling, light, -wi, distance * distance);
      float start = light_start_ratio(eye.sampling, start_over_nee, start_area, dot(x.geometric_normal, wi), 1.0f, eye.pdf_forward);
      float weight = light_subpath_nee_weight(0.0f, start, eye.eye_sum);
      punctual_ray.contribution_state = vec4(vec3(punctual_ray.contribution_state.x, punctual_ray.contribution_state.y,
                                                  punctual_ray.contribution_state.z) * weight, kShadowTrace);
    }
    if (punctual_ray.contribution_state.w != kShadowNone && emitter_guide.punctual_count > 0u) {
      learning.punctual_light = light_index;
      learning.punctual_value = value;
    }
  }
  if (scene_has_environment(SCENE_ALONE_ARG)) {
    vec2 u = sample_2d(rng);
    float pdf_env;
    vec3 wi = scene_sample_environment(SCENE_ARG u.x, u.y, pdf_env);
    float cos_x = dot(x.shading_normal, wi);
    if (pdf_env > 0.0f && cos_x > 0.0f && dot(x.geometric_normal, wi) > 0.0f) {
      float weight = power_heuristic(pdf_env, continuation_pdf(guide, x, wi));
      if (eye.sampling.count > 0.0f && eye.sampling.sky_probability > 0.0f) {
        // The sky's subpaths sample directions as this does: start over NEE = the sky's probability.
        float start = light_start_ratio(eye.sampling, eye.sampling.sky_probability, eye.sampling.disk_density,
                                        dot(x.geometric_normal, wi), 1.0f, eye.pdf_forward);
        weight = light_subpath_nee_weight(continuation_pdf(guide, x, wi) / pdf_env, start, eye.eye_sum);
      }
      environment_ray.direction_length = vec4(wi, uintBitsToFloat(0x7F800000u));
      environment_ray.contribution_state =
          vec4(throughput * (scene_sky_radiance(SCENE_ARG wi) * (cos_x * kInvPi * weight / pdf_env)), kShadowTrace);
    }
  }
}

EXITANCE_FN void next_event_estimation(SCENE_PARAM SurfacePoint x, vec3 origin, vec3 throughput, GuideVertex guide,
                                       EmitterGuide emitter_guide, INOUT(PathSampler) rng, OUT(ShadowRay) area_ray,
                                       OUT(ShadowRay) punctual_ray, OUT(ShadowRay) environment_ray,
                                       OUT(EmitterLearning) learning) {
  next_event_estimation(SCENE_ARG x, origin, throughput, guide, emitter_guide, eye_subpath_vertex_none(), rng, area_ray,
                        punctual_ray, environment_ray, learning);
}

EXITANCE_FN void next_event_estimation(SCENE_PARAM SurfacePoint x, vec3 origin, vec3 throughput, GuideVertex guide,
                                       INOUT(PathSampler) rng, OUT(ShadowRay) area_ray, OUT(ShadowRay) punctual_ray,
                                       OUT(ShadowRay) environment_ray) {
  EmitterLearning learning;
  next_event_estimation(SCENE_ARG x, origin, throughput, guide, emitter_guide_none(), rng, area_ray, punctual_ray,
                        environment_ray, learning);
}

// ---- Light subpaths at the eye's continuation hits (light_subpaths.h) ----
// These read the vertex x the continuation ray wi left through cos_left = dot(x's geometric
// normal, wi) alone (the wavefront keeps that one float per path between its stages).
// light_subpath_emission_extra of a continuation ray from x (state `eye`, emitter strategy
// `emitter_guide`) that hit triangle `tri` (unit geometric normal `ng`, either side) at distance
// t_hit: 0 unless NEE samples it and x is not the texel (the texel never moves to the light side).
EXITANCE_FN float light_subpath_emitter_hit_extra(SCENE_PARAM float cos_left, EyeSubpathVertex eye, EmitterGuide emitter_guide,
                                                  uint tri, vec3 ng, float t_hit, float b1, float b2, vec3 wi) {
  if (!(eye.pdf_forward > 0.0f) || !(scene_triangle_area_pdf(SCENE_ARG tri) > 0.0f)) return 0.0f;
  bool double_sided = material_double_sided(scene_material(SCENE_ARG scene_triangle_material(SCENE_ARG tri)));
  float cos_hit = abs(dot(ng, wi));
  // The subpath's start density over NEE's (emitter guiding at x scales NEE's).
  float start_over_nee =
      eye.sampling.area_probability / emitter_guide_ratio_at_triangle(scene_emitter_cdf(SCENE_ALONE_ARG), emitter_guide, tri, b1, b2);
  float start = light_start_ratio(eye.sampling, start_over_nee, emitter_direction_pdf(cos_hit, double_sided),
                                  cos_left, t_hit * t_hit, eye.pdf_forward);
  return light_subpath_emission_extra(start, eye.eye_sum);
}

// The state of the continuation's hit `next` (unit geometric normal `ng`, either side, at distance
// t_hit along wi, sampled from x with solid-angle density pdf_continuation): the eye's area density
// of it, and C_{j+1} from Q_j, the light side's density of x scattered at `next` over the eye's.
EXITANCE_FN EyeSubpathVertex next_eye_subpath_vertex(EyeSubpathVertex eye, float cos_left, SurfacePoint next, vec3 ng,
                                                     float t_hit, vec3 wi, float pdf_continuation, bool from_texel) {
  float distance2 = t_hit * t_hit;
  float reverse = max(-dot(next.shading_normal, wi), 0.0f) * kInvPi * cos_left / distance2;
  float ratio = !from_texel && eye.pdf_forward > 0.0f ? reverse / eye.pdf_forward : 0.0f;
  EyeSubpathVertex e = eye;
  e.eye_sum = next_eye_sum(from_texel, eye.eye_sum, ratio);
  e.pdf_forward = pdf_continuation * abs(dot(ng, wi)) / distance2;
  return e;
}

// ---- The change of direct light from edited punctual lights (the runtime's refresh) ----
// After an edit that only changed punctual lights, the runtime estimates the change of E/pi from a
// base estimate (RefreshSession, docs/runtime.md): paths are sampled as usual, but each vertex adds
// only the edited lights' direct light as edited minus as it was at the base, both with the same
// shadow-ray origin and path, so where neither version reaches a vertex the change is exactly 0.
// Emission and the sky add nothing (they did not change). Pair k's records are punctual lights
// first + 2k (as edited) and first + 2k + 1 (at the base), after the scene's own; one pair per vertex,
// chosen uniformly (a random number only when there are several), reported in `pair`.
EXITANCE_FN void punctual_change_rays(SCENE_PARAM SurfacePoint x, vec3 throughput, uint first, uint pairs,
                                      INOUT(PathSampler) rng, OUT(ShadowRay) edited_ray, OUT(ShadowRay) base_ray,
                                      OUT(uint) pair) {
  uint k = 0u;
  if (pairs > 1u) k = min(uint(sample_1d(rng) * float(pairs)), pairs - 1u);
  pair = k;
  float probability = 1.0f / float(pairs);
  punctual_light_ray(scene_punctual_light(SCENE_ARG first + 2u * k), x, throughput, probability, edited_ray);
  punctual_light_ray(scene_punctual_light(SCENE_ARG first + 2u * k + 1u), x, -throughput, probability, base_ray);
  // A light that did not move (intensity, colour or cone edited) asks for the same shadow ray twice:
  // one ray carries the difference, which is then exactly 0 wherever the light is occluded.
  if (edited_ray.contribution_state.w == kShadowTrace && base_ray.contribution_state.w == kShadowTrace &&
      edited_ray.direction_length.x == base_ray.direction_length.x && edited_ray.direction_length.y == base_ray.direction_length.y &&
      edited_ray.direction_length.z == base_ray.direction_length.z && edited_ray.direction_length.w == base_ray.direction_length.w) {
    edited_ray.contribution_state = vec4(vec3(edited_ray.contribution_state.x, edited_ray.contribution_state.y, edited_ray.contribution_state.z) +
                                             vec3(base_ray.contribution_state.x, base_ray.contribution_state.y, base_ray.contribution_state.z),
                                         kShadowTrace);
    base_ray = no_shadow_ray();
  }
}

EXITANCE_FN void next_event_estimation(SCENE_PARAM SurfacePoint x, vec3 origin, vec3 throughput, uint strategy,
                                       INOUT(PathSampler) rng, OUT(ShadowRay) area_ray, OUT(ShadowRay) punctual_ray,
                                       OUT(ShadowRay) environment_ray) {
  next_event_estimation(SCENE_ARG x, origin, throughput, guide_vertex_cosine(), rng, area_ray, punctual_ray,
                        environment_ray);
}

// ---- Continuation hits ----
// The sky seen by a continuation ray that escapes, MIS-weighted against environment sampling.
EXITANCE_FN vec3 escaped_radiance(SCENE_PARAM vec3 wi, float pdf_continuation) {
  float weight = 1.0f;
  if (scene_has_environment(SCENE_ALONE_ARG)) weight = power_heuristic(pdf_continuation, scene_environment_pdf(SCENE_ARG wi));
  return scene_sky_radiance(SCENE_ARG wi) * weight;
}

// escaped_radiance for a continuation ray from x (light-subpath state `eye`, the ray's density
// pdf_continuation) when the sky also starts light subpaths (light_subpaths.h): weighed against
// environment sampling and against x's connection to their first hits.
EXITANCE_FN vec3 escaped_radiance_with_subpaths(SCENE_PARAM float cos_left, EyeSubpathVertex eye, vec3 wi, float pdf_continuation) {
  if (!(eye.sampling.count > 0.0f) || !(eye.sampling.sky_probability > 0.0f) || !(eye.pdf_forward > 0.0f))
    return escaped_radiance(SCENE_ARG wi, pdf_continuation);
  float weight;
  if (scene_has_environment(SCENE_ALONE_ARG)) {
    float start = light_start_ratio(eye.sampling, eye.sampling.sky_probability, eye.sampling.disk_density,
                                    cos_left, 1.0f, eye.pdf_forward);
    weight = power_heuristic_with_extra(pdf_continuation, scene_environment_pdf(SCENE_ARG wi),
                                        light_subpath_emission_extra(start, eye.eye_sum));
  } else {
    // No next-event strategy: p_2 / p_0 directly.
    float start = pdf_continuation > 0.0f ? light_start_ratio(eye.sampling, eye.sampling.sky_probability * constant_sky_direction_pdf() / pdf_continuation,
                                                              eye.sampling.disk_density, cos_left, 1.0f, eye.pdf_forward)
                                          : 0.0f;
    weight = light_subpath_nee_weight(0.0f, start, eye.eye_sum);
  }
  return scene_sky_radiance(SCENE_ARG wi) * weight;
}

// The surface point at barycentrics (b1, b2) of triangle t, seen from the side `front` says.
// Shading normals that face away from the geometric side would sample into the surface: replaced.
// `ng`: the triangle's geometric normal (triangle_geometric_normal), which the caller already has.
EXITANCE_FN SurfacePoint surface_point_on_triangle(SCENE_PARAM uint tri, vec3 ng, float b1, float b2, bool front) {
  SurfacePoint x;
  x.geometric_normal = front ? ng : -ng;
  float b0 = 1.0f - b1 - b2;
  x.position = scene_triangle_vertex(SCENE_ARG tri, 0u) * b0 + scene_triangle_vertex(SCENE_ARG tri, 1u) * b1 +
               scene_triangle_vertex(SCENE_ARG tri, 2u) * b2;
  vec3 nv = scene_triangle_normal(SCENE_ARG tri, 0u) * b0 + scene_triangle_normal(SCENE_ARG tri, 1u) * b1 +
            scene_triangle_normal(SCENE_ARG tri, 2u) * b2;
  float len = length(nv);
  vec3 n = len > 0.0f ? nv / len : vec3(0.0f);
  if (!front) n = -n;
  x.shading_normal = dot(n, x.geometric_normal) > 0.05f ? n : x.geometric_normal;
  return x;
}

// What a continuation ray that hit triangle `tri` at distance t adds, and whether the path goes on.
struct HitResult {
  vec3 radiance;     // emitted radiance x MIS weight x throughput, to add at this vertex's bounce
  bool continues;
  vec3 throughput;   // of the continuing path (albedo and roulette applied)
  SurfacePoint next; // the new vertex (when continuing)
};

// `bounce`: the bounce of the vertex the ray left (0 = the texel). Draws one random number when
// Russian roulette is played. `emitter_guide`: the area-light strategy of the vertex the ray left,
// whose density weighs an emitter hit.
// `emission_extra`: light_subpath_emission_extra of the vertex the ray left (0: no light subpaths).
EXITANCE_FN HitResult shade_continuation_hit(SCENE_PARAM uint tri, float t_hit, float b1, float b2, vec3 wi,
                                             float pdf_continuation, vec3 throughput, int bounce, PathLimits limits,
                                             EmitterGuide emitter_guide, float emission_extra, INOUT(PathSampler) rng) {
  HitResult h;
  h.radiance = vec3(0.0f);
  h.continues = false;
  h.throughput = throughput;
  GpuMaterial m = scene_material(SCENE_ARG scene_triangle_material(SCENE_ARG tri));
  bool double_sided = material_double_sided(m);
  vec3 ng = triangle_geometric_normal(SCENE_ARG tri);
  bool front = dot(wi, ng) < 0.0f;
  if (front || double_sided) {
    vec3 le = scene_emission(SCENE_ARG tri, b1, b2);
    if (max_component(le) > 0.0f) {
      float cos_l = abs(dot(wi, ng));
      float pdf_light = scene_triangle_area_pdf(SCENE_ARG tri) * t_hit * t_hit / cos_l;
      pdf_light *= emitter_guide_ratio_at_triangle(scene_emitter_cdf(SCENE_ALONE_ARG), emitter_guide, tri, b1, b2);
      h.radiance = throughput * le * power_heuristic_with_extra(pdf_continuation, pdf_light, emission_extra);
    }
  }
  // Back faces of single-sided surfaces absorb (glTF culls them; light cannot leave through them).
  if (!front && !double_sided) return h;
  if (limits.max_bounces >= 0 && bounce + 1 > limits.max_bounces) return h;
  if (bounce + 1 >= limits.safety_cap) return h;
  h.throughput = throughput * scene_albedo(SCENE_ARG tri, b1, b2);
  if (bounce + 1 >= limits.rr_start) {
    float survive = min(1.0f, max_component(h.throughput));
    if (!(survive > 0.0f)) return h;
    float u = sample_1d(rng);
    if (u >= survive) return h;
    h.throughput = h.throughput / survive;
  } else if (max_component(h.throughput) <= 0.0f) {
    return h;
  }
  h.continues = true;
  h.next = surface_point_on_triangle(SCENE_ARG tri, ng, b1, b2, front);
  return h;
}

EXITANCE_FN HitResult shade_continuation_hit(SCENE_PARAM uint tri, float t_hit, float b1, float b2, vec3 wi,
                                             float pdf_continuation, vec3 throughput, int bounce, PathLimits limits,
                                             EmitterGuide emitter_guide, INOUT(PathSampler) rng) {
  return shade_continuation_hit(SCENE_ARG tri, t_hit, b1, b2, wi, pdf_continuation, throughput, bounce, limits,
                                emitter_guide, 0.0f, rng);
}

EXITANCE_FN HitResult shade_continuation_hit(SCENE_PARAM uint tri, float t_hit, float b1, float b2, vec3 wi,
                                             float pdf_continuation, vec3 throughput, int bounce, PathLimits limits,
                                             INOUT(PathSampler) rng) {
  return shade_continuation_hit(SCENE_ARG tri, t_hit, b1, b2, wi, pdf_continuation, throughput, bounce, limits,
                                emitter_guide_none(), rng);
}

// ---- Light probes ----
// Probe sample `sample` of `spp` (0xFFFFFFFF: unbounded) at probe `probe`: its stratified sphere
// direction, from the 2-D draw of path_sampler(seed, kProbeRngStreamBase + probe, sample); the sampler
// is left positioned for the path that continues from the ray's hit.
EXITANCE_FN vec3 probe_ray_direction(uint sample_index, uint spp, INOUT(PathSampler) rng) {
  vec2 u = sample_2d(rng);
  float u1 = u.x;
  float u2 = u.y;
  uint set_begin = sample_index - sample_index % kProbeStratifiedSetSize;
  uint set_count = min(kProbeStratifiedSetSize, spp - set_begin);
  return probe_direction(sample_index - set_begin, set_count, u1, u2);
}

// What a probe ray meets: a probe is no surface, so there is no next-event estimation at it and the
// emission it sees counts at full weight; the back face of a single-sided surface gives 0 and is
// reported. The hit's albedo multiplies the texel estimator started at `next` (bounces counted from it).
struct ProbeHit {
  vec3 radiance;   // emission seen (0 on a back face)
  vec3 albedo;     // of the hit; the path continues only when it is > 0
  bool back_face;
  bool continues;
  SurfacePoint next;
};

EXITANCE_FN ProbeHit shade_probe_hit(SCENE_PARAM uint tri, float b1, float b2, vec3 wi) {
  ProbeHit h;
  h.radiance = vec3(0.0f);
  h.albedo = vec3(0.0f);
  h.continues = false;
  GpuMaterial m = scene_material(SCENE_ARG scene_triangle_material(SCENE_ARG tri));
  vec3 ng = triangle_geometric_normal(SCENE_ARG tri);
  bool front = dot(wi, ng) < 0.0f;
  h.back_face = !front && !material_double_sided(m);
  if (h.back_face) return h;
  h.radiance = scene_emission(SCENE_ARG tri, b1, b2);
  h.albedo = scene_albedo(SCENE_ARG tri, b1, b2);
  h.continues = max_component(h.albedo) > 0.0f;
  h.next = surface_point_on_triangle(SCENE_ARG tri, ng, b1, b2, front);
  return h;
}

EXITANCE_NAMESPACE_END
#endif
