// Scene data on the GPU: triangles for shading, constant-factor materials, light selection.
// Mirrors runtime/src/{light_sampler.cpp, material_eval.cpp} and distribution_1d.h.
// tri_shading: 6 vec4 per triangle: p0|material bits, p1|area pdf, p2|-, n0, n1, n2.
// materials: 2 vec4: clamped albedo (base colour x (1 - metallic)) | double sided, emission | -.
// punctual: 3 vec4: position|type (0 point, 1 spot, 2 directional), direction|cos_inner, intensity|cos_outer.

vec3 tri_vertex(uint tri, uint k) { return tri_shading[tri * 6u + k].xyz; }
uint tri_material(uint tri) { return floatBitsToUint(tri_shading[tri * 6u].w); }
float tri_area_pdf(uint tri) { return tri_shading[tri * 6u + 1u].w; }
vec3 tri_geometric_normal(uint tri) {
  vec3 p0 = tri_vertex(tri, 0u), p1 = tri_vertex(tri, 1u), p2 = tri_vertex(tri, 2u);
  return normalize(cross(p1 - p0, p2 - p0));
}
vec3 material_albedo(uint m) { return materials[m * 2u].xyz; }
bool material_double_sided(uint m) { return materials[m * 2u].w != 0.0; }
vec3 material_emission(uint m) { return materials[m * 2u + 1u].xyz; }

// Distribution1D::sample: upper_bound over the CDF, then skip zero-weight cells backwards.
uint sample_cdf_emitters(float u, uint n) {
  uint lo = 0u, hi = n + 1u;  // first index with cdf > u in [0, n + 1)
  while (lo < hi) {
    uint mid = (lo + hi) / 2u;
    if (emitter_cdf[mid] > double(u)) hi = mid; else lo = mid + 1u;
  }
  uint i = uint(max(0, int(lo) - 1));
  i = min(i, n - 1u);
  while (float(emitter_cdf[i + 1u] - emitter_cdf[i]) == 0.0 && i > 0u) --i;
  return i;
}
uint sample_cdf_punctual(float u, uint n, out float pmf) {
  uint lo = 0u, hi = n + 1u;
  while (lo < hi) {
    uint mid = (lo + hi) / 2u;
    if (punctual_cdf[mid] > double(u)) hi = mid; else lo = mid + 1u;
  }
  uint i = uint(max(0, int(lo) - 1));
  i = min(i, n - 1u);
  while (float(punctual_cdf[i + 1u] - punctual_cdf[i]) == 0.0 && i > 0u) --i;
  pmf = float(punctual_cdf[i + 1u] - punctual_cdf[i]);
  return i;
}

// Spot falloff of the KHR_lights_punctual reference (squared linear ramp in cos).
float spot_attenuation(vec3 direction, float cos_inner, float cos_outer, vec3 light_to_point) {
  float cd = dot(direction, light_to_point);
  float scale = 1.0 / max(0.001, cos_inner - cos_outer);
  float t = clamp((cd - cos_outer) * scale, 0.0, 1.0);
  return t * t;
}
