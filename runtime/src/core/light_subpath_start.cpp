#include "exitance/runtime/core/light_subpath_start.h"

#include <cmath>

#include "exitance/runtime/core/scene_access.h"

namespace exitance {
namespace {

// The sky's luminance power across the bounding sphere's disc: pi r^2 x its integral over directions.
double sky_subpath_power(const LightingScene& scene, float radius) {
  const double across = M_PI * double(radius) * double(radius);
  if (scene.environment.enabled()) return across * scene.environment.luminance_integral();
  return across * 4.0 * M_PI * double(luminance(scene.sky));
}

}  // namespace

LightSubpathSampling light_subpath_start(const LightingScene& scene) {
  LightSubpathSampling s = light_subpaths_none();
  const float radius = scene_radius(scene);
  const double area_power = scene.emitter_count() > 0 && scene.emitter_inverse_power > 0 ? M_PI / scene.emitter_inverse_power : 0.0;
  // The lights NEE picks (the CDF's mass of the lights with power, 1 up to rounding).
  double punctual_power = scene.punctual_power, punctual_mass = 0;
  for (uint32_t i = 0; i < scene.punctual_count(); ++i) {
    const double pmf = cdf_pmf(scene.punctual_cdf.data(), i);
    if (pmf > 0) punctual_mass += pmf;
  }
  if (!(punctual_mass > 0) || !(punctual_power > 0)) punctual_power = 0;
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

}  // namespace exitance
