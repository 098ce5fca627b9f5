#version 450
// World-space positions (the sample flattens the glTF's node hierarchy on the host) through the
// camera's view-projection; the lightmap UV (TEXCOORD_1) mapped into the instance's page.

layout(push_constant) uniform Draw {
  mat4 view_projection;
  vec4 scale_offset;  // page UV = TEXCOORD_1 * xy + zw (the bundle's per-instance scale_offset)
  vec4 albedo;
  vec4 emission;
  uvec4 flags;        // x: lightmapped, y: double-sided, z: mirrored (front face clockwise)
} draw;

layout(location = 0) in vec3 position;
layout(location = 1) in vec2 lightmap_uv;
layout(location = 0) out vec2 page_uv;

void main() {
  page_uv = lightmap_uv * draw.scale_offset.xy + draw.scale_offset.zw;
  gl_Position = draw.view_projection * vec4(position, 1.0);
}
