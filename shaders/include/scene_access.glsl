// The scene accessors of runtime/common/.../path.h over the descriptor set (C++ twin of the
// interface, over a LightingScene: runtime/include/exitance/runtime/core/scene_access.h). Constant
// material factors only; the host refuses textured materials and environment-map skies.
GpuTriangle scene_triangle(uint t) { return triangles[t]; }
GpuMaterial scene_material(uint m) { return materials[m]; }
GpuPunctualLight scene_punctual_light(uint i) { return punctual[i]; }
uint scene_emitter_count() { return params.emitter_count; }
uint scene_emitter_triangle(uint i) { return emitter_tris[i]; }
uint scene_punctual_count() { return params.punctual_count; }
float scene_extent() { return params.scene_extent; }

const uint kCdfEmitters = 0u;
const uint kCdfPunctual = 1u;
uint scene_emitter_cdf() { return kCdfEmitters; }
uint scene_punctual_cdf() { return kCdfPunctual; }
double cdf_at(uint cdf, uint i) { return cdf == kCdfEmitters ? emitter_cdf[i] : punctual_cdf[i]; }

vec3 scene_albedo(uint t, float b1, float b2) { return materials[floatBitsToUint(triangles[t].p0_material.w)].albedo_double_sided.xyz; }
vec3 scene_emission(uint t, float b1, float b2) { return materials[floatBitsToUint(triangles[t].p0_material.w)].emission.xyz; }
vec3 scene_sky_radiance(vec3 direction) { return params.sky.xyz; }
bool scene_has_environment() { return false; }
float scene_environment_pdf(vec3 direction) { return 0.0; }
vec3 scene_sample_environment(float u1, float u2, out float pdf) {
  pdf = 0.0;
  return vec3(0.0);
}
