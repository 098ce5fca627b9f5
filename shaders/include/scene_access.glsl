// The scene accessors of runtime/common/.../path.h over the descriptor set (C++ twin of the
// interface, over a LightingScene: runtime/include/exitance/runtime/core/scene_access.h). Constant
// material factors only (the host refuses textured materials); an image sky through
// environment_map.h over the environment buffers, as the C++ EnvironmentSampler does.
vec3 scene_triangle_vertex(uint t, uint k) {
  return k == 0u ? triangles[t].p0_material.xyz : (k == 1u ? triangles[t].p1_area_pdf.xyz : triangles[t].p2_instance.xyz);
}
vec3 scene_triangle_normal(uint t, uint k) { return k == 0u ? triangles[t].n0.xyz : (k == 1u ? triangles[t].n1.xyz : triangles[t].n2.xyz); }
uint scene_triangle_material(uint t) { return floatBitsToUint(triangles[t].p0_material.w); }
float scene_triangle_area_pdf(uint t) { return triangles[t].p1_area_pdf.w; }
GpuMaterial scene_material(uint m) { return materials[m]; }
GpuPunctualLight scene_punctual_light(uint i) { return punctual[i]; }
uint scene_emitter_count() { return params.emitter_count; }
uint scene_emitter_triangle(uint i) { return emitter_tris[i]; }
uint scene_punctual_count() { return params.punctual_count; }
float scene_extent() { return params.scene_extent; }

// CDF handles (distribution.h): a buffer each, and past kCdfEnvironmentRows an offset into the
// environment's row CDFs (handle kCdfEnvironmentRows + k starts at entry k).
const uint kCdfEmitters = 0u;
const uint kCdfPunctual = 1u;
const uint kCdfEnvironmentMarginal = 2u;
const uint kCdfEnvironmentRows = 3u;
uint scene_emitter_cdf() { return kCdfEmitters; }
uint scene_punctual_cdf() { return kCdfPunctual; }
double cdf_at(uint cdf, uint i) {
  if (cdf == kCdfEmitters) return emitter_cdf[i];
  if (cdf == kCdfPunctual) return punctual_cdf[i];
  if (cdf == kCdfEnvironmentMarginal) return environment_marginal_cdf[i];
  return environment_row_cdfs[cdf - kCdfEnvironmentRows + i];
}
// After cdf_at, which its CDF sampling reads.
#include "exitance/common/environment_map.h"

vec3 scene_albedo(uint t, float b1, float b2) { return materials[scene_triangle_material(t)].albedo_double_sided.xyz; }
vec3 scene_emission(uint t, float b1, float b2) { return materials[scene_triangle_material(t)].emission.xyz; }
bool scene_has_environment() { return params.environment_width > 0u; }
vec3 scene_sky_radiance(vec3 direction) {
  if (!scene_has_environment()) return params.sky.xyz;
  uint i = environment_texel(direction, params.environment_width, params.environment_height) * 3u;
  return vec3(environment_texels[i], environment_texels[i + 1u], environment_texels[i + 2u]);
}
float scene_environment_pdf(vec3 direction) {
  return environment_direction_pdf(kCdfEnvironmentMarginal, kCdfEnvironmentRows, params.environment_width,
                                   params.environment_height, direction);
}
vec3 scene_sample_environment(float u1, float u2, out float pdf) {
  vec3 direction = sample_environment_direction(kCdfEnvironmentMarginal, kCdfEnvironmentRows, params.environment_width,
                                                params.environment_height, u1, u2);
  pdf = scene_environment_pdf(direction);
  return direction;
}

// Guiding tables are not on the device yet (issue 11: the Vulkan backend refuses --guiding grid),
// so no guided vertex exists here; path.h's guided code still needs the accessor to compile.
float guide_cdf_at(uint cdf, uint i) { return 0.0; }
