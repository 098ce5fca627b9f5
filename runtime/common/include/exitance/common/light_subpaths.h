// Light subpaths shared by every texel (issue 35, item 3): the light-tracing strategies of seed 001
// through a pool of light-subpath vertices (the light vertex cache of Davidovic et al. 2014,
// "Progressive Light Transport Simulation on the GPU"), combined with the path tracer's strategies by
// the power heuristic over every way the same path could have been sampled.
//
// A path x_0 (the texel) ... x_k (a point on a light) is sampled by strategy s (light vertices):
//   s = 0: the eye path hits the emitter;  s = 1: next-event estimation at x_{k-1};
//   s >= 2: eye vertex x_{k-s} connects to light-subpath vertex y_{s-1} = x_{k-s+1} of the pool.
// The texel x_0 is never sampled from the light side (a fixed point, as a pinhole camera's). The
// power-heuristic weight of strategy s is 1 / sum_s' (p_s' / p_s)^2, evaluated from running sums
// (Georgiev 2012, "Implementing Vertex Connection and Merging", without merging; seed 001's ratios):
//   eye side, at x_j: pdf_forward (the area density with which the eye sampled x_j) and eye_sum C_j,
//     the sum over also moving x_{j-1} .. x_1 to the light side once x_j is there (C_1 = 1);
//   light side, at y_i: the reverse ratio (the endpoint factor over the area density with which the
//     light subpath sampled y_i) and B_i = a_i + b_i / n_c^2, the sum over moving y_{i-1} .. y_0 to
//     the eye side once y_i is there.
// Connection strategies count n_c = connections x light subpaths / pool vertices samples per eye
// vertex (the cache's sample count); a connection's contribution is multiplied by 1 / n_c.
// Densities omit Russian roulette on both sides (the same function for every strategy, so the
// weights still sum to 1). Light subpaths start on emissive triangles (by NEE's power CDF, cosine
// directions), on point and spot lights (uniform in their sphere or cone), and from the sky and
// directional lights: a direction (the environment map's importance sampling, uniform for a
// constant sky, the light's own for a directional one), then a point uniform on the disc of the
// scene's bounding sphere across it (area density disk_density), traced into the scene. Such a
// start y_0 lies at infinity: densities toward it are solid-angle ones and y_1's area density is
// disk_density x |cos| (no 1 / d^2). A constant sky has no next-event strategy: there the eye's
// escape (s = 0) takes NEE's place in the sums (y_1 stores the eye's escape density over its own,
// with no further term), and an escape's weight is 1 / (1 + (p_2 / p_0)^2 C_j).
// Eye vertices here sample cosine directions (the texel: its strategy, with the defensive uniform
// component of directional texels): path-guided vertices are not combined yet. Next-event
// estimation may be emitter-guided: its density at the first hit of a subpath is the one the eye
// would use there (the pool is traced with the same frozen tables as the pass's eye paths).
#ifndef EXITANCE_COMMON_LIGHT_SUBPATHS_H
#define EXITANCE_COMMON_LIGHT_SUBPATHS_H
#include "exitance/common/gpu_layout.h"
#include "exitance/common/punctual_light.h"
#include "exitance/common/sampling.h"
EXITANCE_NAMESPACE_BEGIN

// A vertex of a light subpath, as a connection reads it (80 bytes).
struct LightVertex {
  vec4 position_depth;          // xyz; w: depth i >= 1 (uint bits), the edges from the light
  vec4 geometric_normal_layer;  // xyz: unit, on the side the light arrived from; w: light layer (uint bits)
  vec4 shading_normal_ratio;    // xyz: shading normal on that side; w: reverse ratio e_i / p_i
  vec4 weight_a;                // xyz: alpha_i x albedo_i (what a connection multiplies); w: a_i
  vec4 b;                       // x: b_i
};

// How subpaths start, and the pool's counts, as the strategies' densities need them.
struct LightSubpathSampling {
  float area_probability;  // a subpath starts on an emissive triangle (then as NEE picks them)
  float punctual_scale;    // ... at point, spot or directional light L with probability punctual_scale x NEE's pmf(L)
  float sky_probability;   // ... in the sky
  float disk_density;      // 1 / (pi r^2): where the sky's and directional lights' subpaths enter the bounding sphere
  float count;             // n_c, connection strategies' sample count; 0: no pool (no such strategies)
  float scale;             // 1 / n_c: a connection's contribution factor
};

EXITANCE_FN LightSubpathSampling light_subpaths_none() {
  LightSubpathSampling s;
  s.area_probability = 0.0f;
  s.punctual_scale = 0.0f;
  s.sky_probability = 0.0f;
  s.disk_density = 0.0f;
  s.count = 0.0f;
  s.scale = 0.0f;
  return s;
}

// Whether any light starts subpaths.
EXITANCE_FN bool light_subpaths_start_anywhere(LightSubpathSampling s) {
  return s.area_probability > 0.0f || s.punctual_scale > 0.0f || s.sky_probability > 0.0f;
}

// The solid-angle density of an emitter's cosine-distributed direction (double-sided emitters pick
// their side with probability 1/2).
EXITANCE_FN float emitter_direction_pdf(float cos_light, bool double_sided) {
  return abs(cos_light) * kInvPi * (double_sided ? 0.5f : 1.0f);
}

// The solid-angle density of a constant sky's subpath directions (uniform over the sphere).
EXITANCE_FN float constant_sky_direction_pdf() { return 0.25f * kInvPi; }

// The solid-angle density of a punctual light's direction toward `light_to_point` (unit): uniform
// over the sphere (point) or the outer cone (spot); 0 for directional lights (a delta: see
// punctual_start_area_factor).
EXITANCE_FN float punctual_direction_pdf(GpuPunctualLight light, vec3 light_to_point) {
  uint type = floatBitsToUint(light.position_type.w);
  if (type == kPunctualPoint) return 0.25f * kInvPi;
  if (type != kPunctualSpot) return 0.0f;
  float cos_outer = light.intensity_cos_outer.w;
  vec3 axis = vec3(light.direction_cos_inner.x, light.direction_cos_inner.y, light.direction_cos_inner.z);
  if (!(dot(axis, light_to_point) >= cos_outer) || !(cos_outer < 1.0f)) return 0.0f;
  return 1.0f / (2.0f * kPi * (1.0f - cos_outer));
}

// A direction of the spot's outer cone around `axis`, uniform in solid angle.
EXITANCE_FN vec3 sample_spot_cone(vec3 axis, float cos_outer, float u1, float u2) {
  float z = 1.0f - u1 * (1.0f - cos_outer);
  float r = sqrt(max(0.0f, 1.0f - z * z));
  float phi = 2.0f * kPi * u2;
  return to_world(vec3(r * cos(phi), r * sin(phi), z), axis);
}

// The density with which a subpath from punctual light `light` arrives at a point at squared distance
// `distance2` (over |cos| there): its direction density / d^2, or disk_density for a directional light.
EXITANCE_FN float punctual_start_area_factor(LightSubpathSampling s, GpuPunctualLight light, vec3 light_to_point, float distance2) {
  if (floatBitsToUint(light.position_type.w) == kPunctualDirectional) return s.disk_density;
  if (!(distance2 > 0.0f)) return 0.0f;
  return punctual_direction_pdf(light, light_to_point) / distance2;
}

// p_{s+1} / p_s when eye vertex x_j (j >= 1) moves to the light side after next-event estimation
// or an emitter hit: n_c x (the subpath's start density / NEE's) x (the light's direction density
// toward x_j, as an area density at x_j) / the eye's area density of x_j. For a start at infinity
// (the sky, a directional light) pass disk_density as the direction density and distance2 = 1.
EXITANCE_FN float light_start_ratio(LightSubpathSampling s, float start_over_nee, float light_direction_pdf,
                                    float cos_at_vertex, float distance2, float pdf_forward) {
  if (!(pdf_forward > 0.0f) || !(distance2 > 0.0f)) return 0.0f;
  return s.count * start_over_nee * light_direction_pdf * abs(cos_at_vertex) / (distance2 * pdf_forward);
}

// C_{j+1} from x_j's: `ratio` = Q_j, the light side's area density of x_j (scattered at x_{j+1})
// over the eye's; x_0 never moves, so C_1 = 1.
EXITANCE_FN float next_eye_sum(bool from_texel, float eye_sum, float ratio) {
  return from_texel ? 1.0f : 1.0f + ratio * ratio * eye_sum;
}

// Next-event estimation's weight: `continuation_over_light` = p_0 / p_1 (the eye's solid-angle density
// of the light point over NEE's; 0 for punctual lights, which no eye ray hits), `start_ratio` =
// p_2 / p_1 (light_start_ratio; 0 at the texel or without a pool).
EXITANCE_FN float light_subpath_nee_weight(float continuation_over_light, float start_ratio, float eye_sum) {
  return 1.0f / (1.0f + continuation_over_light * continuation_over_light + start_ratio * start_ratio * eye_sum);
}

// (p_2 / p_0)^2 x C_j over (p_1 / p_0)^2, the extra term of an emitter hit's weight
// pdf_continuation^2 / (pdf_continuation^2 + pdf_light^2 (1 + extra)).
EXITANCE_FN float light_subpath_emission_extra(float start_ratio, float eye_sum) {
  return start_ratio * start_ratio * eye_sum;
}

// The power heuristic of an emitter hit against NEE and the strategies with more light vertices.
EXITANCE_FN float power_heuristic_with_extra(float pdf_a, float pdf_b, float extra) {
  float a = pdf_a * pdf_a;
  float b = pdf_b * pdf_b;
  if (!(a > 0.0f)) return 0.0f;
  if (isinf(a)) return 1.0f;
  return a / (a + b * (1.0f + extra));
}

// The sums (a, b) of vertex y_{i+1} from y_i's: `ratio` = the eye's area density of y_i (sampled at
// y_{i+1}) x y_i's reverse ratio; the first hit's (i = 1) carries 1 / n_c, which b keeps apart.
EXITANCE_FN vec2 next_light_sums(uint depth, vec2 sums, float ratio) {
  float r2 = ratio * ratio;
  if (depth == 1u) return vec2(1.0f, r2 * sums.x);
  return vec2(1.0f + r2 * sums.x, r2 * sums.y);
}

// A connection's weight: `eye_density` = the eye's area density of y_i (sampled at x_j),
// `eye_ratio` = Q_j (0 at the texel), `eye_sum` = C_j.
EXITANCE_FN float connection_weight(LightSubpathSampling s, LightVertex y, float eye_density, float eye_ratio, float eye_sum) {
  uint depth = floatBitsToUint(y.position_depth.w);
  float inverse_count = s.scale;
  float r = eye_density * y.shading_normal_ratio.w * (depth == 1u ? inverse_count : 1.0f);
  float fewer = r * r * (y.weight_a.w + y.b.x * inverse_count * inverse_count);
  float more = eye_ratio * eye_ratio * eye_sum;
  return 1.0f / (1.0f + fewer + more);
}

EXITANCE_NAMESPACE_END
#endif
