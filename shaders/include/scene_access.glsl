// The scene accessors of runtime/common/.../path.h over the descriptor set (C++ twin of the
// interface, over a LightingScene: runtime/include/exitance/runtime/core/scene_access.h). Constant
// material factors only; the host refuses textured materials and environment-map skies.
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

const uint kCdfEmitters = 0u;
const uint kCdfPunctual = 1u;
uint scene_emitter_cdf() { return kCdfEmitters; }
uint scene_punctual_cdf() { return kCdfPunctual; }
double cdf_at(uint cdf, uint i) { return cdf == kCdfEmitters ? emitter_cdf[i] : punctual_cdf[i]; }

vec3 scene_albedo(uint t, float b1, float b2) { return materials[scene_triangle_material(t)].albedo_double_sided.xyz; }
vec3 scene_emission(uint t, float b1, float b2) { return materials[scene_triangle_material(t)].emission.xyz; }
vec3 scene_sky_radiance(vec3 direction) { return params.sky.xyz; }
bool scene_has_environment() { return false; }
float scene_environment_pdf(vec3 direction) { return 0.0; }
vec3 scene_sample_environment(float u1, float u2, out float pdf) {
  pdf = 0.0;
  return vec3(0.0);
}

// Guiding tables are not on the device yet (issue 11: the Vulkan backend refuses --guiding grid),
// so no guided vertex exists here; path.h's guided code still needs the accessor to compile.
float guide_cdf_at(uint cdf, uint i) { return 0.0; }
