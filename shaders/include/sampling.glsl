// GLSL twin of runtime/include/exitance/runtime/sampling.h.

// Concentric disk mapping (Shirley & Chiu 1997), then Malley's method: pdf = cos(theta) / pi.
vec3 sample_cosine_hemisphere(float u1, float u2) {
  float a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0;
  float r = 0.0, phi = 0.0;
  if (a != 0.0 || b != 0.0) {
    if (a * a > b * b) { r = a; phi = (kPi / 4.0) * (b / a); }
    else { r = b; phi = (kPi / 2.0) - (kPi / 4.0) * (a / b); }
  }
  float x = r * cos(phi), y = r * sin(phi);
  return vec3(x, y, sqrt(max(0.0, 1.0 - x * x - y * y)));
}

vec3 to_world(vec3 local, vec3 n) {
  vec3 t, b;
  orthonormal_basis(n, t, b);
  return t * local.x + b * local.y + n * local.z;
}

// Heitz 2019: barycentrics (b1, b2) of vertices 1 and 2.
vec2 sample_triangle_barycentrics(float u1, float u2) {
  if (u2 > u1) { float b1 = u1 * 0.5; return vec2(b1, u2 - b1); }
  float b2 = u2 * 0.5;
  return vec2(u1 - b2, b2);
}

// Power heuristic, beta = 2 (Veach 1997).
float power_heuristic(float pdf_a, float pdf_b) {
  float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  if (!(a > 0.0)) return 0.0;
  if (isinf(a)) return 1.0;
  return a / (a + b);
}

vec3 uniform_sphere(float u1, float u2) {
  float z = 1.0 - 2.0 * u1;
  float r = sqrt(max(0.0, 1.0 - z * z));
  float phi = 2.0 * kPi * u2;
  return vec3(r * cos(phi), r * sin(phi), z);
}

// Probe sample `index` of a stratified set of `count` (sampling.h probe_direction): the first m*m
// samples jittered over an m x m grid of the equal-area (z, phi) square, the rest uniform.
vec3 probe_direction(uint index, uint count, float u1, float u2) {
  uint m = uint(sqrt(float(count)));
  while ((m + 1u) * (m + 1u) <= count) ++m;
  while (m > 0u && m * m > count) --m;
  if (index < m * m) {
    float inv = 1.0 / float(m);
    u1 = (float(index % m) + u1) * inv;
    u2 = (float(index / m) + u2) * inv;
  }
  return uniform_sphere(min(u1, 0.99999994), min(u2, 0.99999994));
}
