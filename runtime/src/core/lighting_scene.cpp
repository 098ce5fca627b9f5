#include "exitance/runtime/core/lighting_scene.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "exitance/common/material.h"
#include "exitance/common/punctual_light.h"
#include "exitance/common/sampling.h"
#include "exitance/runtime/distribution_1d.h"
#include "exitance/runtime/material_eval.h"

namespace exitance {
namespace {

float bits_as_float(uint32_t u) { return std::bit_cast<float>(u); }

// A distribution's CDF for a GPU buffer, which must hold at least two entries.
std::vector<double> padded_cdf(const Distribution1D& distribution) {
  std::vector<double> cdf = distribution.cdf();
  if (cdf.size() < 2) cdf.resize(2, 0.0);
  return cdf;
}

// A BVH from elsewhere (scene.bin, the offline stage) must only reference triangles that exist;
// triangles it leaves out (non-finite vertices) are never hit, as on the CPU reference.
void check_bvh_references(const Bvh4& bvh, size_t triangle_count) {
  for (uint32_t t : bvh.leaf_triangles)
    if (t >= triangle_count)
      throw std::invalid_argument("BVH leaf references triangle " + std::to_string(t) + " of " +
                                  std::to_string(triangle_count));
}

}  // namespace

LightingScene build_lighting_scene(std::shared_ptr<const Scene> source, Bvh4 bvh) {
  const Scene& scene = *source;
  const size_t triangle_count = scene.triangle_count();
  check_bvh_references(bvh, triangle_count);
  LightingScene lighting;
  lighting.bvh = std::move(bvh);

  Vec3 lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (const Vec3& p : scene.positions) lo = min(lo, p), hi = max(hi, p);
  if (triangle_count > 0) {
    lighting.bounds_lo = lo, lighting.bounds_hi = hi;
    lighting.extent = std::max(max_component(hi - lo), 1e-30f);
  }
  const float scene_radius = triangle_count > 0 ? std::max(0.5f * length(hi - lo), 1e-6f) : 1.0f;

  // Emitters by power; their area density is what NEE's MIS needs at any hit on them.
  std::vector<double> powers;
  for (uint32_t t = 0; t < triangle_count; ++t) {
    if (!is_emissive(scene, t)) continue;
    const Material& m = scene.materials[scene.triangle_material[t]];
    const double area = triangle_area(scene, t);
    Vec3 mean = m.emission;
    if (m.emissive_texture.texture >= 0) mean = mean * texture_mean(scene.textures[size_t(m.emissive_texture.texture)]);
    const double power = area * double(luminance(mean)) * (m.double_sided ? 2.0 : 1.0);
    if (!(power > 0) || !(area > 0)) continue;  // zero-area or black emitters can never be hit usefully
    lighting.emitter_triangles.push_back(t);
    powers.push_back(power);
  }
  const Distribution1D emitters(powers);
  lighting.emitter_cdf = padded_cdf(emitters);
  std::vector<float> area_pdf(triangle_count, 0.0f);
  for (size_t i = 0; i < lighting.emitter_triangles.size(); ++i) {
    const uint32_t t = lighting.emitter_triangles[i];
    area_pdf[t] = emitters.pmf(i) / triangle_area(scene, t);
  }

  lighting.triangles.resize(triangle_count);
  for (size_t t = 0; t < triangle_count; ++t) {
    const Vec3* p = &scene.positions[t * 3];
    const Vec3* n = &scene.normals[t * 3];
    GpuTriangle& g = lighting.triangles[t];
    g.p0_material = Vec4(p[0], bits_as_float(scene.triangle_material[t]));
    g.p1_area_pdf = Vec4(p[1], area_pdf[t]);
    g.p2_instance = Vec4(p[2], bits_as_float(scene.triangle_instance.empty() ? 0u : scene.triangle_instance[t]));
    g.n0 = Vec4(n[0], 0.0f), g.n1 = Vec4(n[1], 0.0f), g.n2 = Vec4(n[2], 0.0f);
  }

  lighting.materials.resize(scene.materials.size());
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const Material& mat = scene.materials[m];
    if (mat.base_color_texture.texture >= 0 || mat.emissive_texture.texture >= 0) lighting.textured = true;
    const Vec3 emission = max_component(mat.emission) > 0.0f ? mat.emission : Vec3{0, 0, 0};
    lighting.materials[m].albedo_double_sided = Vec4(diffuse_albedo_of(mat.base_color, mat.metallic), mat.double_sided ? 1.0f : 0.0f);
    lighting.materials[m].emission = Vec4(emission, 0.0f);
  }

  std::vector<double> light_powers;
  for (const PunctualLight& light : scene.lights) {
    const double intensity = luminance(light.intensity);
    GpuPunctualLight g;
    uint32_t type = kPunctualPoint;
    switch (light.type) {
      case PunctualLight::Type::Point:
        light_powers.push_back(4.0 * kPi * intensity);
        break;
      case PunctualLight::Type::Spot:
        type = kPunctualSpot;
        light_powers.push_back(2.0 * kPi * (1.0 - light.cos_outer) * intensity);
        break;
      case PunctualLight::Type::Directional:
        type = kPunctualDirectional;
        light_powers.push_back(kPi * double(scene_radius) * double(scene_radius) * intensity);
        break;
    }
    g.position_type = Vec4(light.position, bits_as_float(type));
    g.direction_cos_inner = Vec4(light.direction, light.cos_inner);
    g.intensity_cos_outer = Vec4(light.intensity, light.cos_outer);
    lighting.punctual_lights.push_back(g);
  }
  // An all-zero punctual distribution never samples (pmf 0 -> probability 0).
  lighting.punctual_cdf = padded_cdf(Distribution1D(light_powers));

  lighting.sky = scene.sky.constant;
  lighting.source = std::move(source);
  if (lighting.source->sky.has_environment()) lighting.environment = EnvironmentSampler(lighting.source->sky.environment);
  return lighting;
}

}  // namespace exitance
