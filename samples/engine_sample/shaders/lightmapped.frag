#version 450
// albedo x E/pi + emission: E/pi from the runtime's page image (RGBA32F, layout GENERAL), bilinear
// between texel centres and clamped to the edge as the loader's lookup (and exitance-view) reads it.

layout(push_constant) uniform Draw {
  mat4 view_projection;
  vec4 scale_offset;
  vec4 albedo;
  vec4 emission;
  uvec4 flags;  // x: lightmapped, y: double-sided, z: mirrored
} draw;

// True where the device cannot filter RGBA32F linearly (not guaranteed by Vulkan): the sampler is
// then NEAREST and the shader blends the four texels itself, with the loader's formula.
layout(constant_id = 0) const bool kManualBilinear = false;

layout(set = 0, binding = 0) uniform sampler2D lightmap;  // one set per page

layout(location = 0) in vec2 page_uv;
layout(location = 0) out vec4 color;

vec3 bilinear(vec2 uv) {
  const ivec2 size = textureSize(lightmap, 0);
  const vec2 x = clamp(uv * vec2(size) - 0.5, vec2(0.0), vec2(size - 1));
  const ivec2 i0 = min(ivec2(floor(x)), size - 1), i1 = min(i0 + 1, size - 1);
  const vec2 t = x - vec2(i0);
  const vec3 top = mix(texelFetch(lightmap, i0, 0).rgb, texelFetch(lightmap, ivec2(i1.x, i0.y), 0).rgb, t.x);
  const vec3 bottom = mix(texelFetch(lightmap, ivec2(i0.x, i1.y), 0).rgb, texelFetch(lightmap, i1, 0).rgb, t.x);
  return mix(top, bottom, t.y);
}

void main() {
  // glTF's front face is counter-clockwise, clockwise under a mirroring transform.
  const bool front = gl_FrontFacing != (draw.flags.z != 0u);
  // The back of a single-sided surface is black, as bake treats it and exitance-view draws it
  // (runtime/src/view/view_shading.cpp); a double-sided one shows its lightmap and emission on both.
  if (!front && draw.flags.y == 0u) {
    color = vec4(0.0, 0.0, 0.0, 1.0);
    return;
  }
  vec3 e_over_pi = vec3(0.0);  // instances without a lightmap: emission only (an engine would use probes)
  if (draw.flags.x != 0u) e_over_pi = kManualBilinear ? bilinear(page_uv) : textureLod(lightmap, page_uv, 0.0).rgb;
  color = vec4(draw.albedo.rgb * e_over_pi + draw.emission.rgb, 1.0);
}
