// The scene accessors of runtime/common/.../path.h for C++ code (the CPU reference, tests): reads a
// LightingScene. Textured materials are evaluated here from the source Scene; the shaders' accessors
// (shaders/include/scene_access.glsl) read constant factors only and the Vulkan backend refuses
// scenes that need more (LightingScene::textured). Image skies go through environment_map.h on both.
#pragma once
#include "exitance/common/gpu_layout.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/material_eval.h"

namespace exitance {

inline vec3 scene_triangle_vertex(const LightingScene& scene, uint t, uint k) {
  const GpuTriangle& g = scene.triangles[t];
  const Vec4& v = k == 0 ? g.p0_material : (k == 1 ? g.p1_emitter : g.p2_instance);
  return {v.x, v.y, v.z};
}
inline vec3 scene_triangle_normal(const LightingScene& scene, uint t, uint k) {
  const GpuTriangle& g = scene.triangles[t];
  const Vec4& n = k == 0 ? g.n0 : (k == 1 ? g.n1 : g.n2);
  return {n.x, n.y, n.z};
}
inline uint scene_triangle_material(const LightingScene& scene, uint t) { return floatBitsToUint(scene.triangles[t].p0_material.w); }
inline float scene_triangle_area_pdf(const LightingScene& scene, uint t) {
  // The emitter flag times its material's power per area first (exact), then the total's inverse.
  return scene.triangles[t].p1_emitter.w * scene.materials[scene_triangle_material(scene, t)].emitter_power.x * scene.emitter_inverse_power;
}
inline GpuMaterial scene_material(const LightingScene& scene, uint m) { return scene.materials[m]; }
inline GpuPunctualLight scene_punctual_light(const LightingScene& scene, uint i) { return scene.punctual_lights[i]; }
inline uint scene_emitter_count(const LightingScene& scene) { return scene.emitter_count(); }
inline uint scene_emitter_triangle(const LightingScene& scene, uint i) { return scene.emitter_triangles[i]; }
inline uint scene_punctual_count(const LightingScene& scene) { return scene.punctual_count(); }
inline const double* scene_emitter_cdf(const LightingScene& scene) { return scene.emitter_cdf.data(); }
inline const double* scene_punctual_cdf(const LightingScene& scene) { return scene.punctual_cdf.data(); }
inline float scene_extent(const LightingScene& scene) { return scene.extent; }

inline vec3 scene_albedo(const LightingScene& scene, uint t, float b1, float b2) {
  if (!scene.textured) {
    const Vec4 a = scene.materials[floatBitsToUint(scene.triangles[t].p0_material.w)].albedo_double_sided;
    return {a.x, a.y, a.z};
  }
  return diffuse_albedo(*scene.source, t, b1, b2);
}
inline vec3 scene_emission(const LightingScene& scene, uint t, float b1, float b2) {
  if (!scene.textured) {
    const Vec4 e = scene.materials[floatBitsToUint(scene.triangles[t].p0_material.w)].emission;
    return {e.x, e.y, e.z};
  }
  return emitted_radiance(*scene.source, t, b1, b2);
}

inline bool scene_has_environment(const LightingScene& scene) { return scene.environment.enabled(); }
inline vec3 scene_sky_radiance(const LightingScene& scene, vec3 direction) {
  return scene.environment.enabled() ? scene.environment.radiance(direction) : scene.sky;
}
inline float scene_environment_pdf(const LightingScene& scene, vec3 direction) { return scene.environment.pdf(direction); }
inline vec3 scene_sample_environment(const LightingScene& scene, float u1, float u2, float& pdf) {
  return scene.environment.sample(u1, u2, pdf);
}

}  // namespace exitance

#include "exitance/common/path.h"
