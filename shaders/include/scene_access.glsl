// The scene accessors of runtime/common/.../path.h over the descriptor set (C++ twin of the
// interface, over a LightingScene: runtime/include/exitance/runtime/core/scene_access.h). Materials
// with textures, COLOR_0 and alphaMode are evaluated per point as runtime/src/material_eval.cpp and
// alpha_coverage.cpp do, through the same shared math; an image sky through environment_map.h over the
// environment buffer, as the C++ EnvironmentSampler does.
#include "exitance/common/material.h"
#include "exitance/common/surface_alpha.h"
#include "exitance/common/texture_sampling.h"

vec3 scene_triangle_vertex(uint t, uint k) {
  return k == 0u ? triangles[t].p0_material.xyz : (k == 1u ? triangles[t].p1_emitter.xyz : triangles[t].p2_instance.xyz);
}
vec3 scene_triangle_normal(uint t, uint k) { return k == 0u ? triangles[t].n0.xyz : (k == 1u ? triangles[t].n1.xyz : triangles[t].n2.xyz); }
uint scene_triangle_material(uint t) { return floatBitsToUint(triangles[t].p0_material.w); }
// The emitter flag times its material's power per area first (exact), then the total's inverse.
float scene_triangle_area_pdf(uint t) {
  return triangles[t].p1_emitter.w * materials[scene_triangle_material(t)].emitter_power.x * params.emitter_inverse_power;
}
GpuMaterial scene_material(uint m) { return materials[m]; }
GpuPunctualLight scene_punctual_light(uint i) { return punctual[i]; }
uint scene_emitter_count() { return params.emitter_count; }
uint scene_emitter_triangle(uint i) { return emitter_tris[i]; }
uint scene_punctual_count() { return params.punctual_count; }
float scene_extent() { return params.scene_extent; }

// CDF handles (distribution.h): a buffer each, and past kCdfEnvironmentRows an offset into the
// environment's row CDFs (handle kCdfEnvironmentRows + k starts at row entry k; environment_map.h
// has the buffer's offsets).
const uint kCdfEmitters = 0u;
const uint kCdfPunctual = 1u;
const uint kCdfEnvironmentMarginal = 2u;
const uint kCdfEnvironmentRows = 3u;
uint scene_emitter_cdf() { return kCdfEmitters; }
uint scene_punctual_cdf() { return kCdfPunctual; }
double cdf_at(uint cdf, uint i) {
  if (cdf == kCdfEmitters) return emitter_cdf[i];
  if (cdf == kCdfPunctual) return punctual_cdf[i];
  if (cdf == kCdfEnvironmentMarginal) return environment[i];
  return environment[params.environment_height + 1u + cdf - kCdfEnvironmentRows + i];
}
// After cdf_at, which its CDF sampling reads.
#include "exitance/common/environment_map.h"

// Texel rgb k of the image sky: floats packed two to a double after the CDFs.
float environment_texel_channel(uint k) {
  uvec2 halves = unpackDouble2x32(environment[environment_texels_offset(params.environment_width, params.environment_height) + k / 2u]);
  return uintBitsToFloat((k & 1u) == 0u ? halves.x : halves.y);
}

// ---- Per-point surfaces (params.surface_flags), read from the packed surface words ----
uvec4 surface_header() { return floatBitsToUint(surfaces[0]); }  // textures, corner uvs, corner colours, texels

GpuMaterialSurface material_surface(uint m) {
  uint b = kSurfaceHeaderWords + m * kMaterialSurfaceWords;
  GpuMaterialSurface s;
  s.base_color_metallic = surfaces[b];
  s.base_offset_scale = surfaces[b + 1u];
  s.emissive_offset_scale = surfaces[b + 2u];
  s.rotations_alpha = surfaces[b + 3u];
  s.textures_mode = surfaces[b + 4u];
  return s;
}

GpuTexture texture_record(uint i) {
  uvec4 w = floatBitsToUint(surfaces[surface_header().x + i]);
  GpuTexture t;
  t.texel_offset = w.x;
  t.width = w.y;
  t.height = w.z;
  t.wrap_alpha = w.w;
  return t;
}

vec4 interpolate_corners(uint first, uint t, float b1, float b2) {
  uint b = first + t * 3u;
  return surfaces[b] * (1.0 - b1 - b2) + surfaces[b + 1u] * b1 + surfaces[b + 2u] * b2;
}
vec4 interpolate_corners_uv(uint t, float b1, float b2) { return interpolate_corners(surface_header().y, t, b1, b2); }
vec4 interpolate_corners_color(uint t, float b1, float b2) { return interpolate_corners(surface_header().z, t, b1, b2); }

// The texture coordinate a binding reads: its TEXCOORD set (0: uv0, 1: lightmap uv), transformed.
vec2 binding_uv(uint t, float b1, float b2, uint tex_coord, vec4 offset_scale, float rotation) {
  vec4 uvs = interpolate_corners_uv(t, b1, b2);
  return transform_texture_coordinate(tex_coord == 1u ? uvs.zw : uvs.xy, offset_scale.xy, offset_scale.zw, rotation);
}

vec4 texel_at(GpuTexture tex, int x, int y) { return surfaces[surface_header().w + tex.texel_offset + uint(y) * tex.width + uint(x)]; }

BilinearTaps texture_taps(GpuTexture tex, vec2 uv) {
  return bilinear_taps(uv, int(tex.width), int(tex.height), tex.wrap_alpha & 0xFFu, (tex.wrap_alpha >> 8u) & 0xFFu);
}

vec3 sample_texture_rgb(uint texture_index, vec2 uv) {
  GpuTexture tex = texture_record(texture_index);
  BilinearTaps taps = texture_taps(tex, uv);
  return bilinear_mix(texel_at(tex, taps.x0, taps.y0).xyz, texel_at(tex, taps.x1, taps.y0).xyz,
                      texel_at(tex, taps.x0, taps.y1).xyz, texel_at(tex, taps.x1, taps.y1).xyz, taps);
}

float sample_texture_alpha(uint texture_index, vec2 uv) {
  GpuTexture tex = texture_record(texture_index);
  if ((tex.wrap_alpha & kTextureHasAlpha) == 0u) return 1.0;
  BilinearTaps taps = texture_taps(tex, uv);
  return bilinear_mix(texel_at(tex, taps.x0, taps.y0).w, texel_at(tex, taps.x1, taps.y0).w, texel_at(tex, taps.x0, taps.y1).w,
                      texel_at(tex, taps.x1, taps.y1).w, taps);
}

// base_alpha x base colour texture alpha x COLOR_0 alpha, clamped (alpha_coverage.cpp surface_coverage).
float surface_coverage(uint t, float b1, float b2, GpuMaterialSurface m) {
  float coverage = m.rotations_alpha.w;
  uint base_texture = floatBitsToUint(m.textures_mode.x);
  if (base_texture != kNoTexture) {
    uint tex_coord = floatBitsToUint(m.textures_mode.z) & 0xFFu;
    coverage *= sample_texture_alpha(base_texture, binding_uv(t, b1, b2, tex_coord, m.base_offset_scale, m.rotations_alpha.x));
  }
  if ((params.surface_flags & kSurfaceVertexAlpha) != 0u) coverage *= interpolate_corners_color(t, b1, b2).w;
  return clamped_coverage(coverage);
}

// Whether a hit stops the ray (alpha_coverage.cpp hit_is_opaque with blend_decision_number);
// traversal asks only when params.surface_flags has kSurfaceAlphaMaterials.
bool scene_hit_stops_ray(uint t, float b1, float b2, vec3 origin, vec3 direction) {
  GpuMaterialSurface m = material_surface(scene_triangle_material(t));
  uint mode = floatBitsToUint(m.textures_mode.w);
  if (mode == kAlphaOpaque) return true;
  float u = mode == kAlphaBlend ? blend_decision_number(origin, direction, t) : 0.0;
  return coverage_stops_ray(mode, surface_coverage(t, b1, b2, m), m.rotations_alpha.z, u);
}

// material_eval.cpp diffuse_albedo: base colour x texture x COLOR_0, then the diffuse part.
vec3 textured_albedo(uint t, float b1, float b2) {
  GpuMaterialSurface m = material_surface(scene_triangle_material(t));
  vec3 base = m.base_color_metallic.xyz;
  uint base_texture = floatBitsToUint(m.textures_mode.x);
  if (base_texture != kNoTexture) {
    uint tex_coord = floatBitsToUint(m.textures_mode.z) & 0xFFu;
    base *= sample_texture_rgb(base_texture, binding_uv(t, b1, b2, tex_coord, m.base_offset_scale, m.rotations_alpha.x));
  }
  if ((params.surface_flags & kSurfaceVertexColor) != 0u) base *= interpolate_corners_color(t, b1, b2).xyz;
  return diffuse_albedo_of(base, m.base_color_metallic.w);
}

// material_eval.cpp emitted_radiance: the factor x emissive texture, zero where MASK lets rays pass.
vec3 textured_emission(uint t, float b1, float b2) {
  uint material = scene_triangle_material(t);
  vec3 emission = materials[material].emission.xyz;
  if (max(emission.x, max(emission.y, emission.z)) <= 0.0) return vec3(0.0);
  GpuMaterialSurface m = material_surface(material);
  if (floatBitsToUint(m.textures_mode.w) == kAlphaMask && surface_coverage(t, b1, b2, m) < m.rotations_alpha.z) return vec3(0.0);
  uint emissive_texture = floatBitsToUint(m.textures_mode.y);
  if (emissive_texture == kNoTexture) return emission;
  uint tex_coord = (floatBitsToUint(m.textures_mode.z) >> 8u) & 0xFFu;
  return emission * sample_texture_rgb(emissive_texture, binding_uv(t, b1, b2, tex_coord, m.emissive_offset_scale, m.rotations_alpha.y));
}

vec3 scene_albedo(uint t, float b1, float b2) {
  if ((params.surface_flags & kSurfaceTextured) != 0u) return textured_albedo(t, b1, b2);
  return materials[scene_triangle_material(t)].albedo_double_sided.xyz;
}
vec3 scene_emission(uint t, float b1, float b2) {
  if ((params.surface_flags & kSurfaceTextured) != 0u) return textured_emission(t, b1, b2);
  return materials[scene_triangle_material(t)].emission.xyz;
}
bool scene_has_environment() { return params.environment_width > 0u; }
vec3 scene_sky_radiance(vec3 direction) {
  if (!scene_has_environment()) return params.sky.xyz;
  uint i = environment_texel(direction, params.environment_width, params.environment_height) * 3u;
  return vec3(environment_texel_channel(i), environment_texel_channel(i + 1u), environment_texel_channel(i + 2u));
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

// Grid guiding's CDFs (guided_direction.h) live in the guide buffer (gpu_layout.h kBindingGuide): a
// handle is the word offset of its record's CDF (guide.glsl guide_vertex_of).
float guide_cdf_at(uint cdf, uint i) { return uintBitsToFloat(guide_words[cdf + i]); }
// Emitter guiding's tables (guided_emitters.h) live there too: a handle is a word offset.
uint emitter_guide_word(uint table, uint i) { return guide_words[table + i]; }
