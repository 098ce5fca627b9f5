#include "exitance/runtime/light_sampler.h"

#include <cmath>

#include "exitance/runtime/material_eval.h"
#include "exitance/runtime/sampling.h"

namespace exitance {

LightSampler::LightSampler(const Scene& scene)
    : scene_(scene), triangle_area_pdf_(scene.triangle_count(), 0.0f) {
  Vec3 lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
  for (const Vec3& p : scene.positions) lo = min(lo, p), hi = max(hi, p);
  scene_radius_ = scene.positions.empty() ? 1.0f : std::max(0.5f * length(hi - lo), 1e-6f);

  std::vector<double> powers;
  for (uint32_t t = 0; t < scene.triangle_count(); ++t) {
    if (!is_emissive(scene, t)) continue;
    const Material& m = scene.materials[scene.triangle_material[t]];
    const double area = triangle_area(scene, t);
    Vec3 mean = m.emission;
    if (m.emissive_texture.texture >= 0) mean = mean * texture_mean(scene.textures[size_t(m.emissive_texture.texture)]);
    const double power = area * double(luminance(mean)) * (m.double_sided ? 2.0 : 1.0);
    if (!(power > 0) || !(area > 0)) continue;  // zero-area or black emitters can never be hit usefully
    emitter_triangles_.push_back(t);
    powers.push_back(power);
  }
  emitters_ = Distribution1D(powers);
  for (size_t i = 0; i < emitter_triangles_.size(); ++i) {
    const uint32_t t = emitter_triangles_[i];
    triangle_area_pdf_[t] = emitters_.pmf(i) / triangle_area(scene, t);
  }

  std::vector<double> light_powers;
  for (const PunctualLight& light : scene.lights) {
    const double intensity = luminance(light.intensity);
    switch (light.type) {
      case PunctualLight::Type::Point: light_powers.push_back(4.0 * kPi * intensity); break;
      case PunctualLight::Type::Spot: light_powers.push_back(2.0 * kPi * (1.0 - light.cos_outer) * intensity); break;
      case PunctualLight::Type::Directional:
        light_powers.push_back(kPi * double(scene_radius_) * double(scene_radius_) * intensity);
        break;
    }
  }
  punctual_ = Distribution1D(light_powers);
  if (scene.sky.has_environment()) environment_ = EnvironmentSampler(scene.sky.environment);
}

AreaLightSample LightSampler::sample_area_light(float u_choose, float u1, float u2) const {
  const size_t i = emitters_.sample(u_choose);
  const uint32_t t = emitter_triangles_[i];
  const Vec3* p = &scene_.positions[size_t(t) * 3];
  AreaLightSample s;
  sample_triangle_barycentrics(u1, u2, s.b1, s.b2);
  s.position = p[0] * (1.0f - s.b1 - s.b2) + p[1] * s.b1 + p[2] * s.b2;
  s.normal = triangle_normal(scene_, t);
  s.triangle = t;
  s.pdf_area = triangle_area_pdf_[t];
  return s;
}

const PunctualLight& LightSampler::sample_punctual(float u, float& probability) const {
  const size_t i = punctual_.sample(u);
  probability = punctual_.pmf(i);
  return scene_.lights[i];
}

}  // namespace exitance
