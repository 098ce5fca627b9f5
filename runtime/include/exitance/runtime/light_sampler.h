// Next-event estimation: picks emissive triangles by power (uniform area sampling on the
// chosen one), punctual lights by power, and the sky map by its own distribution.
#pragma once
#include "exitance/runtime/distribution_1d.h"
#include "exitance/runtime/environment_sampler.h"
#include "exitance/runtime/scene.h"

namespace exitance {

struct AreaLightSample {
  Vec3 position;
  Vec3 normal;       // front-side geometric normal of the emitter
  uint32_t triangle;
  float b1, b2;
  float pdf_area;    // probability density per unit area (includes the triangle choice)
};

class LightSampler {
 public:
  explicit LightSampler(const Scene& scene);

  bool has_area_lights() const { return !emitters_.empty(); }
  bool has_punctual_lights() const { return !punctual_.empty(); }
  AreaLightSample sample_area_light(float u_choose, float u1, float u2) const;
  // Area density with which `triangle` would have been sampled at any point on it.
  float area_pdf(uint32_t triangle) const { return triangle_area_pdf_[triangle]; }

  const PunctualLight& sample_punctual(float u, float& probability) const;

  const EnvironmentSampler& environment() const { return environment_; }
  // The distributions themselves, for backends that sample on another device.
  const std::vector<uint32_t>& emitter_triangles() const { return emitter_triangles_; }
  const Distribution1D& emitter_distribution() const { return emitters_; }
  const Distribution1D& punctual_distribution() const { return punctual_; }
  float scene_radius() const { return scene_radius_; }

 private:
  const Scene& scene_;
  std::vector<uint32_t> emitter_triangles_;
  Distribution1D emitters_;
  std::vector<float> triangle_area_pdf_;  // per scene triangle; 0 for non-emitters
  Distribution1D punctual_;
  EnvironmentSampler environment_;
  float scene_radius_ = 1.0f;
};

}  // namespace exitance
