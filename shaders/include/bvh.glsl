// BVH4 traversal (built by Embree's rtcBuildBVH, runtime/src/vulkan/gpu_bvh.cpp).
// Node = 7 vec4: lo.x[4], hi.x[4], lo.y[4], hi.y[4], lo.z[4], hi.z[4], child[4] (uint bits).
// Child word: kInvalid = empty, bit 31 set = leaf (first triangle << 2 | count - 1), else inner node index.
// Triangles: watertight test of Woop, Benthin & Wald (JCGT 2013), double-precision fallback on edges.

layout(constant_id = 0) const uint kStackSize = 64u;  // host sets the exact bound of this BVH
const uint kLeafBit = 0x80000000u;
const float kBoxRobustScale = 1.0 + 2.0 * 3.0 * 5.96046448e-8 / (1.0 - 3.0 * 5.96046448e-8);  // 1 + 2 gamma(3)

struct Ray {
  vec3 origin;
  vec3 inv_dir;
  int kx, ky, kz;
  vec3 shear;  // Sx, Sy, Sz
};

Ray make_ray(vec3 o, vec3 d) {
  Ray r;
  r.origin = o;
  // Zero components would give 0 * inf = NaN in the slab test; a tiny stand-in keeps it conservative.
  vec3 safe_d = mix(d, sign(d + 1e-38) * 1e-20, lessThan(abs(d), vec3(1e-20)));
  r.inv_dir = 1.0 / safe_d;
  vec3 ad = abs(d);
  r.kz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
  r.kx = (r.kz + 1) % 3;
  r.ky = (r.kx + 1) % 3;
  if (d[r.kz] < 0.0) { int t = r.kx; r.kx = r.ky; r.ky = t; }
  r.shear = vec3(d[r.kx] / d[r.kz], d[r.ky] / d[r.kz], 1.0 / d[r.kz]);
  return r;
}

// Returns t (> 0) and barycentrics of vertices 1 and 2, or t = -1.
vec3 intersect_triangle(Ray r, vec3 v0, vec3 v1, vec3 v2, out float t_out) {
  t_out = -1.0;
  vec3 a = v0 - r.origin, b = v1 - r.origin, c = v2 - r.origin;
  float ax = a[r.kx] - r.shear.x * a[r.kz], ay = a[r.ky] - r.shear.y * a[r.kz];
  float bx = b[r.kx] - r.shear.x * b[r.kz], by = b[r.ky] - r.shear.y * b[r.kz];
  float cx = c[r.kx] - r.shear.x * c[r.kz], cy = c[r.ky] - r.shear.y * c[r.kz];
  float u = cx * by - cy * bx, v = ax * cy - ay * cx, w = bx * ay - by * ax;
  if (u == 0.0 || v == 0.0 || w == 0.0) {
    u = float(double(cx) * double(by) - double(cy) * double(bx));
    v = float(double(ax) * double(cy) - double(ay) * double(cx));
    w = float(double(bx) * double(ay) - double(by) * double(ax));
  }
  if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) return vec3(0.0);
  float det = u + v + w;
  if (det == 0.0) return vec3(0.0);
  float az = r.shear.z * a[r.kz], bz = r.shear.z * b[r.kz], cz = r.shear.z * c[r.kz];
  float t = (u * az + v * bz + w * cz) / det;
  t_out = t;
  return vec3(u, v, w) / det;
}

// Closest hit in (0, t_max). Returns (t, triangle bits, b1, b2); triangle = kInvalid on a miss.
// `steps` counts loop iterations (for lane-efficiency statistics).
vec4 trace_closest(vec3 o, vec3 d, float t_max, inout uint steps) {
  Ray r = make_ray(o, d);
  float best_t = t_max;
  uint best_tri = kInvalid;
  float best_b1 = 0.0, best_b2 = 0.0;
  uint stack[kStackSize];
  uint sp = 0u;
  uint node = 0u;
  while (true) {
    ++steps;
    if ((node & kLeafBit) != 0u) {
      uint first = (node & 0x7FFFFFFFu) >> 2u, count = (node & 3u) + 1u;
      for (uint i = 0u; i < count; ++i) {
        uint base = (first + i) * 3u;
        vec4 p0 = leaf_tris[base], p1 = leaf_tris[base + 1u], p2 = leaf_tris[base + 2u];
        float t;
        vec3 bary = intersect_triangle(r, p0.xyz, p1.xyz, p2.xyz, t);
        if (t > 0.0 && t < best_t) {
          best_t = t;
          best_tri = floatBitsToUint(p0.w);
          best_b1 = bary.y;
          best_b2 = bary.z;
        }
      }
    } else {
      uint b = node * 7u;
      vec4 t0x = (nodes[b + 0u] - r.origin.x) * r.inv_dir.x, t1x = (nodes[b + 1u] - r.origin.x) * r.inv_dir.x;
      vec4 t0y = (nodes[b + 2u] - r.origin.y) * r.inv_dir.y, t1y = (nodes[b + 3u] - r.origin.y) * r.inv_dir.y;
      vec4 t0z = (nodes[b + 4u] - r.origin.z) * r.inv_dir.z, t1z = (nodes[b + 5u] - r.origin.z) * r.inv_dir.z;
      uvec4 child = floatBitsToUint(nodes[b + 6u]);
      vec4 tnear = max(max(min(t0x, t1x), min(t0y, t1y)), max(min(t0z, t1z), vec4(0.0)));
      vec4 tfar = min(min(max(t0x, t1x), max(t0y, t1y)), min(max(t0z, t1z), vec4(best_t))) * kBoxRobustScale;
      bvec4 hit = bvec4(uvec4(lessThanEqual(tnear, tfar)) * uvec4(notEqual(child, uvec4(kInvalid))));
      // Push far-to-near so the nearest child is popped first (insertion sort of at most 4).
      float keys[4];
      uint ids[4];
      uint n = 0u;
      for (int i = 0; i < 4; ++i) {
        if (!hit[i]) continue;
        float k = tnear[i];
        uint j = n;
        while (j > 0u && keys[j - 1u] < k) { keys[j] = keys[j - 1u]; ids[j] = ids[j - 1u]; --j; }
        keys[j] = k;
        ids[j] = child[i];
        ++n;
      }
      for (uint i = 0u; i < n; ++i) stack[sp++] = ids[i];
    }
    if (sp == 0u) break;
    node = stack[--sp];
  }
  return vec4(best_t, uintBitsToFloat(best_tri), best_b1, best_b2);
}

// Any hit in (0, t_max]: true when something blocks the segment.
bool trace_any(vec3 o, vec3 d, float t_max, inout uint steps) {
  Ray r = make_ray(o, d);
  uint stack[kStackSize];
  uint sp = 0u;
  uint node = 0u;
  while (true) {
    ++steps;
    if ((node & kLeafBit) != 0u) {
      uint first = (node & 0x7FFFFFFFu) >> 2u, count = (node & 3u) + 1u;
      for (uint i = 0u; i < count; ++i) {
        uint base = (first + i) * 3u;
        float t;
        intersect_triangle(r, leaf_tris[base].xyz, leaf_tris[base + 1u].xyz, leaf_tris[base + 2u].xyz, t);
        if (t > 0.0 && t <= t_max) return true;
      }
    } else {
      uint b = node * 7u;
      vec4 t0x = (nodes[b + 0u] - r.origin.x) * r.inv_dir.x, t1x = (nodes[b + 1u] - r.origin.x) * r.inv_dir.x;
      vec4 t0y = (nodes[b + 2u] - r.origin.y) * r.inv_dir.y, t1y = (nodes[b + 3u] - r.origin.y) * r.inv_dir.y;
      vec4 t0z = (nodes[b + 4u] - r.origin.z) * r.inv_dir.z, t1z = (nodes[b + 5u] - r.origin.z) * r.inv_dir.z;
      uvec4 child = floatBitsToUint(nodes[b + 6u]);
      vec4 tnear = max(max(min(t0x, t1x), min(t0y, t1y)), max(min(t0z, t1z), vec4(0.0)));
      vec4 tfar = min(min(max(t0x, t1x), max(t0y, t1y)), min(max(t0z, t1z), vec4(t_max))) * kBoxRobustScale;
      for (int i = 0; i < 4; ++i)
        if (tnear[i] <= tfar[i] && child[i] != kInvalid) stack[sp++] = child[i];
    }
    if (sp == 0u) break;
    node = stack[--sp];
  }
  return false;
}
