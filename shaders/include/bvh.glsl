// BVH4 traversal (built by Embree's rtcBuildBVH, runtime/src/cpu/bvh4_builder.cpp; core/bvh4.h).
// Two node layouts, chosen by the host (specialization constant 1, kQuantizedNodes):
// float: 7 vec4 (112 bytes): lo.x[4], hi.x[4], lo.y[4], hi.y[4], lo.z[4], hi.z[4], child[4] (uint bits);
// quantized: 4 uvec4 (64 bytes): origin, per-axis power-of-two scales and 8-bit child planes
// (quantize_bvh4_nodes in runtime/src/vulkan/bvh_quantization.h), then child[4].
// Child word: kInvalid = empty, bit 31 set = leaf (first triangle << 2 | count - 1), else inner node index.
// MASK/BLEND (params.surface_flags & kSurfaceAlphaMaterials): a hit where scene_hit_stops_ray says
// the surface lets the ray pass is skipped, and the search goes on, as Embree's filter does on the CPU.
// Triangles: watertight test of Woop, Benthin & Wald (JCGT 2013), double-precision fallback on edges.
//
// Traversal keeps the next node in a register: of the children a ray enters, the nearest is visited
// next and only the others go to the stack (far first), sorted by a 4-input sorting network on
// registers (no dynamically indexed arrays besides the stack itself). Loops are "while-while"
// (Aila & Laine 2009): inner nodes until the lane reaches a leaf, then the leaf, so the lanes of a
// subgroup run the triangle tests together; closest hit too since 2026-12-01 (+2 % building, +6 % open
// city on the H200 against one loop that took a leaf or an inner node per iteration; keeping a leaf
// back until every lane holds one, Aila & Laine's speculative variant, lost 18-22 %:
// bench/results/open-city-gpu.md). Measured: bench/results/vulkan-{lavapipe,gpu}.md.

layout(constant_id = 0) const uint kStackSize = 64u;  // host sets the exact bound of this BVH
layout(constant_id = 1) const bool kQuantizedNodes = false;
// Every loop here is bounded: a valid BVH visits each node and leaf at most once per ray, so more
// steps than params.traversal_steps (the host sets nodes + leaf slots), or a push past kStackSize,
// means corrupt nodes or a broken invariant. The ray then ends (a miss; occluded for trace_any),
// and counters[kCounterFaultTraversal] counts it so the host fails the run with a message instead
// of a shader that never returns (lavapipe has no GPU watchdog).
const uint kLeafBit = 0x80000000u;
const float kBoxRobustScale = 1.0 + 2.0 * 3.0 * 5.96046448e-8 / (1.0 - 3.0 * 5.96046448e-8);  // 1 + 2 gamma(3)

struct Ray {
  vec3 origin;
  vec3 inv_dir;
  // Rows of the watertight test's permute-and-shear transform: for a = v - origin,
  // (a[kx] - Sx a[kz], a[ky] - Sy a[kz], Sz a[kz]) = (dot(a, row_x), dot(a, row_y), dot(a, row_z)).
  // Each row has at most two non-zero entries, so the dot products round exactly like the
  // component expressions; no dynamic vector indexing per triangle.
  vec3 row_x, row_y, row_z;
};

vec3 unit_axis(int k) { return vec3(k == 0 ? 1.0 : 0.0, k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0); }

Ray make_ray(vec3 o, vec3 d) {
  Ray r;
  r.origin = o;
  // Zero components would give 0 * inf = NaN in the slab test; a tiny stand-in keeps it conservative.
  vec3 safe_d = mix(d, sign(d + 1e-38) * 1e-20, lessThan(abs(d), vec3(1e-20)));
  r.inv_dir = 1.0 / safe_d;
  vec3 ad = abs(d);
  int kz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
  int kx = (kz + 1) % 3;
  int ky = (kx + 1) % 3;
  if (d[kz] < 0.0) { int t = kx; kx = ky; ky = t; }
  vec3 ex = unit_axis(kx), ey = unit_axis(ky), ez = unit_axis(kz);
  float dz = d[kz];
  float sx = d[kx] / dz, sy = d[ky] / dz, sz = 1.0 / dz;
  r.row_x = ex - sx * ez;
  r.row_y = ey - sy * ez;
  r.row_z = sz * ez;
  return r;
}

// Returns barycentrics (u, v, w) / det and t (> 0) through t_out, or t_out = -1.
vec3 intersect_triangle(Ray r, vec3 v0, vec3 v1, vec3 v2, out float t_out) {
  t_out = -1.0;
  vec3 a = v0 - r.origin, b = v1 - r.origin, c = v2 - r.origin;
  float ax = dot(a, r.row_x), ay = dot(a, r.row_y);
  float bx = dot(b, r.row_x), by = dot(b, r.row_y);
  float cx = dot(c, r.row_x), cy = dot(c, r.row_y);
  float u = cx * by - cy * bx, v = ax * cy - ay * cx, w = bx * ay - by * ax;
  if (u == 0.0 || v == 0.0 || w == 0.0) {
    u = float(double(cx) * double(by) - double(cy) * double(bx));
    v = float(double(ax) * double(cy) - double(ay) * double(cx));
    w = float(double(bx) * double(ay) - double(by) * double(ax));
  }
  if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) return vec3(0.0);
  float det = u + v + w;
  if (det == 0.0) return vec3(0.0);
  float az = dot(a, r.row_z), bz = dot(b, r.row_z), cz = dot(c, r.row_z);
  float t = (u * az + v * bz + w * cz) / det;
  t_out = t;
  return vec3(u, v, w) / det;
}

vec4 decode_planes(float origin, uint bytes, float scale) {
  vec4 q = vec4(uvec4(bytes, bytes >> 8u, bytes >> 16u, bytes >> 24u) & 0xFFu);
  return origin + q * scale;  // q * scale is exact: the host computed the same floats (bvh_quantization.h)
}

// Slab test of the 4 children of inner node `node` against (0, t_max]; misses get tnear = +inf.
vec4 intersect_children(Ray r, uint node, float t_max, out uvec4 child) {
  if (!kQuantizedNodes) {
    uint b = node * 7u;
    vec4 t0x = (uintBitsToFloat(nodes[b + 0u]) - r.origin.x) * r.inv_dir.x;
    vec4 t1x = (uintBitsToFloat(nodes[b + 1u]) - r.origin.x) * r.inv_dir.x;
    vec4 t0y = (uintBitsToFloat(nodes[b + 2u]) - r.origin.y) * r.inv_dir.y;
    vec4 t1y = (uintBitsToFloat(nodes[b + 3u]) - r.origin.y) * r.inv_dir.y;
    vec4 t0z = (uintBitsToFloat(nodes[b + 4u]) - r.origin.z) * r.inv_dir.z;
    vec4 t1z = (uintBitsToFloat(nodes[b + 5u]) - r.origin.z) * r.inv_dir.z;
    child = nodes[b + 6u];
    vec4 tnear = max(max(min(t0x, t1x), min(t0y, t1y)), max(min(t0z, t1z), vec4(0.0)));
    vec4 tfar = min(min(max(t0x, t1x), max(t0y, t1y)), min(max(t0z, t1z), vec4(t_max))) * kBoxRobustScale;
    bvec4 hit = bvec4(uvec4(lessThanEqual(tnear, tfar)) * uvec4(notEqual(child, uvec4(kInvalid))));
    return mix(vec4(kInfinity), tnear, hit);
  }
  uint b = node * 4u;
  uvec4 w0 = nodes[b], w1 = nodes[b + 1u], w2 = nodes[b + 2u], w3 = nodes[b + 3u];
  vec3 origin = uintBitsToFloat(w0.xyz);
  vec3 scale = uintBitsToFloat(((uvec3(w0.w) >> uvec3(0u, 8u, 16u)) & 0xFFu) << 23u);
  vec4 t0x = (decode_planes(origin.x, w1.x, scale.x) - r.origin.x) * r.inv_dir.x;
  vec4 t1x = (decode_planes(origin.x, w1.y, scale.x) - r.origin.x) * r.inv_dir.x;
  vec4 t0y = (decode_planes(origin.y, w1.z, scale.y) - r.origin.y) * r.inv_dir.y;
  vec4 t1y = (decode_planes(origin.y, w1.w, scale.y) - r.origin.y) * r.inv_dir.y;
  vec4 t0z = (decode_planes(origin.z, w2.x, scale.z) - r.origin.z) * r.inv_dir.z;
  vec4 t1z = (decode_planes(origin.z, w2.y, scale.z) - r.origin.z) * r.inv_dir.z;
  child = uvec4(w2.zw, w3.xy);
  vec4 tnear = max(max(min(t0x, t1x), min(t0y, t1y)), max(min(t0z, t1z), vec4(0.0)));
  vec4 tfar = min(min(max(t0x, t1x), max(t0y, t1y)), min(max(t0z, t1z), vec4(t_max))) * kBoxRobustScale;
  bvec4 hit = bvec4(uvec4(lessThanEqual(tnear, tfar)) * uvec4(notEqual(child, uvec4(kInvalid))));
  return mix(vec4(kInfinity), tnear, hit);
}

void traversal_fault() { atomicAdd(counters[kCounterFaultTraversal], 1u); }

// Compare-exchange of entries i < j by key (ascending).
#define BVH_CSWAP(K, C, i, j)                                   \
  {                                                             \
    bool s = K[j] < K[i];                                       \
    float kt = K[i]; uint ct = C[i];                            \
    K[i] = s ? K[j] : K[i]; C[i] = s ? C[j] : C[i];             \
    K[j] = s ? kt : K[j]; C[j] = s ? ct : C[j];                 \
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
  uint budget = params.traversal_steps;
  bool fault = false;  // breaks out of both loops (a return inside them cost lavapipe 2x the compile time)
  while (node != kInvalid) {
    while (node != kInvalid && (node & kLeafBit) == 0u) {
      ++steps;
      uvec4 child;
      vec4 key = intersect_children(r, node, best_t, child);
      // Sort ascending (5 compare-exchanges); misses (+inf) sink to the end.
      BVH_CSWAP(key, child, 0, 1);
      BVH_CSWAP(key, child, 2, 3);
      BVH_CSWAP(key, child, 0, 2);
      BVH_CSWAP(key, child, 1, 3);
      BVH_CSWAP(key, child, 1, 2);
      // Far children to the stack first, the nearest stays in a register.
      uint pushes = uint(key.w != kInfinity) + uint(key.z != kInfinity) + uint(key.y != kInfinity);
      if (sp + pushes > kStackSize || --budget == 0u) { fault = true; node = kInvalid; break; }
      if (key.w != kInfinity) stack[sp++] = child.w;
      if (key.z != kInfinity) stack[sp++] = child.z;
      if (key.y != kInfinity) stack[sp++] = child.y;
      node = key.x != kInfinity ? child.x : (sp == 0u ? kInvalid : stack[--sp]);
    }
    // Leaves until the next inner node (or the end).
    while (node != kInvalid && (node & kLeafBit) != 0u) {
      ++steps;
      if (--budget == 0u) { fault = true; node = kInvalid; break; }
      uint first = (node & 0x7FFFFFFFu) >> 2u, count = (node & 3u) + 1u;
      for (uint i = 0u; i < count; ++i) {
        uint base = (first + i) * 3u;
        vec4 p0 = leaf_tris[base], p1 = leaf_tris[base + 1u], p2 = leaf_tris[base + 2u];
        float t;
        vec3 bary = intersect_triangle(r, p0.xyz, p1.xyz, p2.xyz, t);
        if (t > 0.0 && t < best_t &&
            ((params.surface_flags & kSurfaceAlphaMaterials) == 0u || scene_hit_stops_ray(floatBitsToUint(p0.w), bary.y, bary.z, o, d))) {
          best_t = t;
          best_tri = floatBitsToUint(p0.w);
          best_b1 = bary.y;
          best_b2 = bary.z;
        }
      }
      node = sp == 0u ? kInvalid : stack[--sp];
    }
  }
  if (fault) {
    traversal_fault();
    return vec4(t_max, uintBitsToFloat(kInvalid), 0.0, 0.0);
  }
  return vec4(best_t, uintBitsToFloat(best_tri), best_b1, best_b2);
}

// Any hit in (0, t_max]: true when something blocks the segment. Child order does not matter here:
// the first child entered stays in a register, the others are pushed unsorted.
bool trace_any(vec3 o, vec3 d, float t_max, inout uint steps) {
  Ray r = make_ray(o, d);
  uint stack[kStackSize];
  uint sp = 0u;
  uint node = 0u;
  uint budget = params.traversal_steps;
  bool fault = false;
  while (node != kInvalid) {
    while (node != kInvalid && (node & kLeafBit) == 0u) {
      ++steps;
      uvec4 child;
      vec4 key = intersect_children(r, node, t_max, child);
      uint pushes = uint(key.x != kInfinity) + uint(key.y != kInfinity) + uint(key.z != kInfinity) + uint(key.w != kInfinity);
      if (sp + max(pushes, 1u) - 1u > kStackSize || --budget == 0u) { fault = true; node = kInvalid; break; }
      uint next = kInvalid;
      for (int i = 3; i >= 0; --i) {
        if (key[i] == kInfinity) continue;
        if (next != kInvalid) stack[sp++] = next;
        next = child[i];
      }
      node = next != kInvalid ? next : (sp == 0u ? kInvalid : stack[--sp]);
    }
    if (node == kInvalid) break;
    ++steps;
    if (--budget == 0u) { fault = true; break; }
    uint first = (node & 0x7FFFFFFFu) >> 2u, count = (node & 3u) + 1u;
    for (uint i = 0u; i < count; ++i) {
      uint base = (first + i) * 3u;
      float t;
      vec3 bary = intersect_triangle(r, leaf_tris[base].xyz, leaf_tris[base + 1u].xyz, leaf_tris[base + 2u].xyz, t);
      if (t > 0.0 && t <= t_max &&
          ((params.surface_flags & kSurfaceAlphaMaterials) == 0u ||
           scene_hit_stops_ray(floatBitsToUint(leaf_tris[base].w), bary.y, bary.z, o, d)))
        return true;
    }
    node = sp == 0u ? kInvalid : stack[--sp];
  }
  if (fault) traversal_fault();
  return fault;  // a faulted ray counts as blocked
}
