// Light subpaths for the pool (light_vertex_pool.h). Each subpath carries alpha, its throughput in
// the eye estimator's measure (what the path's contribution f has so far over the densities that
// sampled it), and the MIS sums of light_subpaths.h.
#include "light_vertex_pool.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>

#include "exitance/common/light_layers.h"
#include "exitance/runtime/core/emitter_guiding_cache.h"
#include "exitance/runtime/embree_scene.h"

namespace exitance {
namespace {

// Luminance power of a punctual light: point 4 pi I, spot 2 pi (1 - cos_outer) I, directional
// pi r^2 E across the bounding sphere's disc (as the punctual CDF weighs them).
double punctual_subpath_power(const GpuPunctualLight& light, float radius) {
  const uint32_t type = floatBitsToUint(light.position_type.w);
  const double intensity = luminance(vec3(light.intensity_cos_outer.x, light.intensity_cos_outer.y, light.intensity_cos_outer.z));
  if (type == kPunctualPoint) return 4.0 * M_PI * intensity;
  if (type == kPunctualSpot) return 2.0 * M_PI * (1.0 - double(light.intensity_cos_outer.w)) * intensity;
  if (type == kPunctualDirectional) return M_PI * double(radius) * double(radius) * intensity;
  return 0.0;
}

// The sky's luminance power across the bounding sphere's disc: pi r^2 x its integral over directions.
double sky_subpath_power(const LightingScene& scene, float radius) {
  const double across = M_PI * double(radius) * double(radius);
  if (scene.environment.enabled()) return across * scene.environment.luminance_integral();
  return across * 4.0 * M_PI * double(luminance(scene.sky));
}

struct PathStart {
  bool valid = false;
  bool area = false;
  bool sky = false;
  bool infinite = false;  // the sky or a directional light: y_0 at infinity, y_1 by disk_density
  Vec3 beta{0, 0, 0};  // L_e cos / p_start (emitter) or I attenuation / p_start (punctual)
  Vec3 origin{0, 0, 0};
  Vec3 direction{0, 0, 0};
  float pdf_direction = 0;  // solid angle; disk_density for a start at infinity
  float cos_light = 0;  // at an emitter point, toward the direction (for y_1's eye density of y_0)
  float nee_area_pdf = 0;  // NEE's by power (unguided)
  float start_probability = 0;  // the subpath's density of its start (area density, or the light's probability)
  uint32_t triangle = 0, light = 0;
  vec2 barycentrics{0, 0};
  uint32_t layer = 0;
};

struct PoolTracer {
  const LightingScene& scene;
  const EmbreeScene& embree;
  LightSubpathSampling start;
  std::vector<double> punctual_cdf;     // over subpath_lights, by NEE's pmf
  std::vector<uint32_t> subpath_lights;  // the punctual lights
  Vec3 centre;                           // of the bounding sphere, radius `radius`
  float radius;
  int max_depth;
  int rr_start;
  EmitterGuidingCache* emitter_guide;

  // NEE's density of the subpath's start from y (its learned sampling there, if any); for a constant
  // sky, which NEE does not sample, the eye's escape density toward it (light_subpaths.h).
  float nee_density(const PathStart& s, const SurfacePoint& y) const {
    if (s.sky) {
      const Vec3 toward_sky = -s.direction;
      if (scene.environment.enabled()) return scene.environment.pdf(toward_sky);
      return std::max(dot(y.shading_normal, toward_sky), 0.0f) * kInvPi;
    }
    const EmitterGuide g =
        EmitterGuidingCache::vertex_site(emitter_guide, y.position, y.shading_normal, EmitterGuidingCache::Learning::None).guide;
    if (s.area) return s.nee_area_pdf * emitter_guide_ratio_at_triangle(scene_emitter_cdf(scene), g, s.triangle, s.barycentrics.x, s.barycentrics.y);
    return punctual_mixture_probability(scene_punctual_cdf(scene), g, s.light);
  }

  PathStart start_on_emitter(float u_choose, PathSampler& rng) const {
    PathStart p;
    const vec2 u = sample_2d(rng);
    const EmitterPoint point = emitter_mixture_sample(scene_emitter_cdf(scene), scene_emitter_count(scene), emitter_guide_none(),
                                                      u_choose, u.x, u.y);
    const uint32_t tri = scene_emitter_triangle(scene, point.emitter);
    const vec3 p0 = scene_triangle_vertex(scene, tri, 0), p1 = scene_triangle_vertex(scene, tri, 1), p2 = scene_triangle_vertex(scene, tri, 2);
    const vec2 b = point.barycentrics;
    const vec3 position = p0 * (1.0f - b.x - b.y) + p1 * b.x + p2 * b.y;
    const vec3 ng = normalize(cross(p1 - p0, p2 - p0));
    const bool double_sided = material_double_sided(scene_material(scene, scene_triangle_material(scene, tri)));
    vec3 n = ng;
    if (double_sided && sample_1d(rng) < 0.5f) n = -ng;
    const vec2 ud = sample_2d(rng);
    const vec3 local = sample_cosine_hemisphere(ud.x, ud.y);
    if (!(local.z > 0)) return p;
    p.nee_area_pdf = scene_triangle_area_pdf(scene, tri);
    const float p_start = start.area_probability * p.nee_area_pdf;
    if (!(p_start > 0)) return p;
    p.valid = true;
    p.area = true;
    p.direction = to_world(local, n);
    p.cos_light = local.z;
    p.pdf_direction = emitter_direction_pdf(local.z, double_sided);
    p.beta = scene_emission(scene, tri, b.x, b.y) * (local.z / p_start);
    p.origin = offset_ray_origin(position, n, scene_extent(scene));
    p.start_probability = p_start;
    p.triangle = tri;
    p.barycentrics = b;
    p.layer = uint32_t(scene.materials[scene_triangle_material(scene, tri)].emission.w);
    return p;
  }

  // A start at infinity travelling along `direction`: a point uniform on the bounding sphere's disc
  // across it, outside the sphere.
  void enter_from_infinity(PathStart& p, Vec3 direction, PathSampler& rng) const {
    const vec2 u = sample_2d(rng);
    const float r = radius * std::sqrt(u.x), phi = 2.0f * kPi * u.y;
    p.origin = centre - direction * radius + to_world(vec3(r * std::cos(phi), r * std::sin(phi), 0.0f), direction);
    p.direction = direction;
    p.pdf_direction = start.disk_density;
    p.infinite = true;
  }

  PathStart start_in_sky(PathSampler& rng) const {
    PathStart p;
    const vec2 u = sample_2d(rng);
    float pdf = constant_sky_direction_pdf();
    const Vec3 toward_sky = scene.environment.enabled() ? scene.environment.sample(u.x, u.y, pdf) : uniform_sphere(u.x, u.y);
    const float p_start = start.sky_probability * pdf;
    const Vec3 radiance = scene_sky_radiance(scene, toward_sky);
    if (!(p_start > 0) || !(max_component(radiance) > 0)) return p;
    enter_from_infinity(p, -toward_sky, rng);
    p.valid = true;
    p.sky = true;
    p.beta = radiance / p_start;
    p.start_probability = p_start;
    p.layer = kSkyLightLayer;
    return p;
  }

  PathStart start_at_punctual(float u_choose, PathSampler& rng) const {
    PathStart p;
    float pmf = 0;
    const uint32_t k = sample_cdf(punctual_cdf.data(), uint(subpath_lights.size()), u_choose, pmf);
    const uint32_t index = subpath_lights[k];
    const GpuPunctualLight light = scene_punctual_light(scene, index);
    const float p_start = start.punctual_scale * cdf_pmf(scene_punctual_cdf(scene), index);
    const vec3 axis = vec3(light.direction_cos_inner.x, light.direction_cos_inner.y, light.direction_cos_inner.z);
    if (floatBitsToUint(light.position_type.w) == kPunctualDirectional) {
      if (!(p_start > 0)) return p;
      enter_from_infinity(p, axis, rng);
      p.valid = true;
      p.beta = vec3(light.intensity_cos_outer.x, light.intensity_cos_outer.y, light.intensity_cos_outer.z) / p_start;
      p.start_probability = p_start;
      p.light = index;
      p.layer = punctual_light_layer(index, scene.punctual_light_layers);
      return p;
    }
    const vec2 u = sample_2d(rng);
    const bool spot = floatBitsToUint(light.position_type.w) == kPunctualSpot;
    const vec3 direction = spot ? sample_spot_cone(axis, light.intensity_cos_outer.w, u.x, u.y) : uniform_sphere(u.x, u.y);
    p.pdf_direction = punctual_direction_pdf(light, direction);
    if (!(p.pdf_direction > 0) || !(p_start > 0)) return p;
    const float attenuation =
        spot ? spot_attenuation(axis, light.direction_cos_inner.w, light.intensity_cos_outer.w, direction) : 1.0f;
    if (!(attenuation > 0)) return p;
    p.valid = true;
    p.direction = direction;
    p.beta = vec3(light.intensity_cos_outer.x, light.intensity_cos_outer.y, light.intensity_cos_outer.z) * (attenuation / p_start);
    p.origin = vec3(light.position_type.x, light.position_type.y, light.position_type.z);
    p.start_probability = p_start;
    p.light = index;
    p.layer = punctual_light_layer(index, scene.punctual_light_layers);
    return p;
  }

  // One subpath; its vertices appended to `out`.
  void trace(uint64_t path, uint64_t seed, uint32_t key, uint32_t sampler, std::vector<LightVertex>& out, uint64_t& rays) const {
    PathSampler rng = path_sampler(seed, kLightSubpathStreamBase + path, key, sampler);
    const float u = sample_1d(rng);
    const float sky_end = start.area_probability + start.sky_probability;
    const bool sky = start.sky_probability > 0 && u >= start.area_probability && (u < sky_end || subpath_lights.empty());
    PathStart s = u < start.area_probability ? start_on_emitter(rescaled_unit(u, 0.0f, start.area_probability), rng)
                  : sky                      ? start_in_sky(rng)
                                             : start_at_punctual(rescaled_unit(u, sky_end, 1.0f - sky_end), rng);
    if (!s.valid) return;
    Vec3 beta = s.beta, origin = s.origin, direction = s.direction;
    float pdf_direction = s.pdf_direction;
    float cos_previous = s.cos_light;  // |cos| at the previous vertex toward this edge
    vec2 sums{0, 0};
    float ratio = 0;
    for (uint32_t depth = 1;; ++depth) {
      ++rays;
      const Hit hit = embree.intersect(origin, direction, INFINITY);
      if (!hit.found) return;
      const uint32_t tri = hit.triangle;
      const bool double_sided = material_double_sided(scene_material(scene, scene_triangle_material(scene, tri)));
      const vec3 ng = triangle_geometric_normal(scene, tri);
      const bool front = dot(direction, ng) < 0.0f;
      if (!front && !double_sided) return;  // single-sided back faces absorb
      const SurfacePoint y = surface_point_on_triangle(scene, tri, ng, hit.b1, hit.b2, front);
      const float cos_geometric = std::fabs(dot(ng, direction));
      const float cos_shading = -dot(y.shading_normal, direction);
      // From infinity the first hit's density is disk_density x cos (no 1 / d^2).
      const float distance2 = depth == 1 && s.infinite ? 1.0f : hit.distance * hit.distance;
      if (!(cos_shading > 0) || !(cos_geometric > 0) || !(distance2 > 0)) return;
      const float reverse_density = pdf_direction * cos_geometric / distance2;
      const Vec3 alpha = beta * (cos_shading * kInvPi / (pdf_direction * cos_geometric));
      // The eye's area density of the previous vertex, sampled (cosine) here.
      // (a solid-angle density toward a start at infinity).
      const float eye_density = cos_shading * kInvPi * (depth == 1 && s.infinite ? 1.0f : cos_previous / distance2);
      vec2 next_sums;
      float next_ratio;
      if (depth == 1) {
        const float nee = nee_density(s, y);
        if (!(nee > 0)) return;  // NEE samples every light it can start from
        // y_0 hit by the eye against NEE (an emitter, an environment map; a constant sky's NEE is that hit).
        const float r0 = s.area || (s.sky && scene.environment.enabled()) ? eye_density / nee : 0.0f;
        next_sums = vec2(1.0f + r0 * r0, 0.0f);
        next_ratio = nee / s.start_probability / reverse_density;  // e_1 / p_1
      } else {
        next_sums = next_light_sums(depth - 1, sums, eye_density * ratio);
        next_ratio = 1.0f / reverse_density;
      }
      const Vec3 albedo = scene_albedo(scene, tri, hit.b1, hit.b2);
      if (!(max_component(albedo) > 0)) return;
      const Vec3 weight = alpha * albedo;
      LightVertex v;
      v.position_depth = vec4(y.position, uintBitsToFloat(depth));
      v.geometric_normal_layer = vec4(y.geometric_normal, uintBitsToFloat(s.layer));
      v.shading_normal_ratio = vec4(y.shading_normal, next_ratio);
      v.weight_a = vec4(weight, next_sums.x);
      v.b = vec4(next_sums.y, 0.0f, 0.0f, 0.0f);
      if (is_finite(weight) && std::isfinite(next_ratio) && std::isfinite(next_sums.x) && std::isfinite(next_sums.y))
        out.push_back(v);
      if (int(depth) >= max_depth) return;
      Vec3 carried = weight;
      if (int(depth) >= rr_start) {
        const float survive = std::min(1.0f, max_component(albedo));
        if (sample_1d(rng) >= survive) return;
        carried = carried / survive;
      }
      const DirectionSample d = sample_continuation(kStrategyCosine, y, rng);
      if (!(d.pdf > 0)) return;
      cos_previous = std::fabs(dot(y.geometric_normal, d.direction));
      beta = carried * cos_previous;
      pdf_direction = d.pdf;
      origin = offset_ray_origin(y.position, y.geometric_normal, scene_extent(scene));
      direction = d.direction;
      sums = next_sums;
      ratio = next_ratio;
    }
  }
};

}  // namespace

LightSubpathSampling light_subpath_start(const LightingScene& scene) {
  LightSubpathSampling s = light_subpaths_none();
  const float radius = scene_radius(scene);
  const double area_power = scene.emitter_count() > 0 && scene.emitter_inverse_power > 0 ? M_PI / scene.emitter_inverse_power : 0.0;
  double punctual_power = 0, punctual_mass = 0;
  for (uint32_t i = 0; i < scene.punctual_count(); ++i) {
    const double power = punctual_subpath_power(scene.punctual_lights[i], radius);
    if (power > 0) punctual_power += power, punctual_mass += cdf_pmf(scene.punctual_cdf.data(), i);
  }
  if (!(punctual_mass > 0)) punctual_power = 0;
  double sky_power = scene.triangles.empty() ? 0.0 : sky_subpath_power(scene, radius);
  if (!(sky_power > 0) || !std::isfinite(sky_power)) sky_power = 0;
  const double total = area_power + punctual_power + sky_power;
  if (!(total > 0)) return s;
  s.area_probability = float(area_power / total);
  s.sky_probability = float(sky_power / total);
  s.punctual_scale = punctual_power > 0 ? float(punctual_power / total / punctual_mass) : 0.0f;
  s.disk_density = float(1.0 / (M_PI * double(radius) * double(radius)));
  return s;
}

LightVertexPool trace_light_vertex_pool(const LightingScene& scene, const EmbreeScene& embree, LightSubpathSampling start,
                                        uint64_t paths, uint64_t seed, uint32_t key, uint32_t sampler, int max_depth,
                                        int rr_start, EmitterGuidingCache* emitter_guide) {
  LightVertexPool pool;
  pool.max_depth = max_depth;
  if (paths == 0 || max_depth < 1 || !light_subpaths_start_anywhere(start)) return pool;
  const float radius = scene_radius(scene);
  PoolTracer tracer{scene, embree, start, {0.0}, {}, (scene.bounds_lo + scene.bounds_hi) * 0.5f, radius, max_depth, rr_start, emitter_guide};
  for (uint32_t i = 0; i < scene.punctual_count(); ++i)
    if (punctual_subpath_power(scene.punctual_lights[i], radius) > 0) {
      tracer.subpath_lights.push_back(i);
      tracer.punctual_cdf.push_back(tracer.punctual_cdf.back() + cdf_pmf(scene.punctual_cdf.data(), i));
    }
  for (double& c : tracer.punctual_cdf) c /= std::max(tracer.punctual_cdf.back(), 1e-300);
  if (tracer.subpath_lights.empty()) tracer.punctual_cdf.push_back(1.0);
  // Blocks of paths in parallel, concatenated in path order.
  constexpr uint64_t kBlock = 256;
  const uint64_t blocks = (paths + kBlock - 1) / kBlock;
  std::vector<std::vector<LightVertex>> block_vertices(blocks);
  std::vector<uint64_t> block_rays(blocks, 0);
  tbb::parallel_for(tbb::blocked_range<uint64_t>(0, blocks), [&](const tbb::blocked_range<uint64_t>& range) {
    for (uint64_t b = range.begin(); b != range.end(); ++b)
      for (uint64_t p = b * kBlock; p < std::min(paths, (b + 1) * kBlock); ++p)
        tracer.trace(p, seed, key, sampler, block_vertices[b], block_rays[b]);
  });
  size_t total = 0;
  for (const auto& v : block_vertices) total += v.size();
  pool.vertices.reserve(total);
  for (uint64_t b = 0; b < blocks; ++b) {
    pool.vertices.insert(pool.vertices.end(), block_vertices[b].begin(), block_vertices[b].end());
    pool.rays += block_rays[b];
  }
  pool.paths = paths;
  pool.sampling = start;
  if (!pool.vertices.empty()) {
    // One connection per eye vertex: n_c = paths / vertices.
    pool.sampling.count = float(double(paths) / double(pool.vertices.size()));
    pool.sampling.scale = float(double(pool.vertices.size()) / double(paths));
  }
  return pool;
}

}  // namespace exitance
