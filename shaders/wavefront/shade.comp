#version 460
#extension GL_GOOGLE_include_directive : require
// Stage "shade": at each extension ray's hit: sky on a miss, emission with MIS, absorption by back
// faces, bounce limits, albedo, Russian roulette; then next-event estimation and the cosine-sampled
// continuation at the new vertex. Finished paths are regenerated from the batch's work.
// Probe batches (the kProbeMode variant): depth 0 is the ray from the probe: emission at full weight
// (nothing to MIS with), 0 and a back-face mark on single-sided back faces, and the hit's albedo kept
// apart (the reference multiplies the hit's whole E/pi estimate by it); the path from the hit is the
// texel estimator with its depth counted from 1, so bounce limits and roulette use depth - 1.
layout(local_size_x = 64) in;
#include "../include/kernel_prelude.glsl"

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= counters[kRayCount0 + push.cur]) return;
  uint p = ray_queue[push.cur * params.path_capacity + i];
  vec4 hit = path_hit[p];
  uint tri = floatBitsToUint(hit.y);
  uint work = path_work[p], depth = path_depth[p];
  vec4 tp = path_throughput[p];
  vec3 throughput = tp.xyz;
  float pdf_cosine = tp.w;
  vec3 wi = path_ray_d[p].xyz;
  u64vec2 rs = path_rng[p];
  Pcg32 rng;
  rng.state = rs.x;
  rng.increment = rs.y;

  bool continues = false;
  bool probe_ray = kProbeMode && depth == 0u;
  SurfacePoint x;
  if (tri == kInvalid) {
    add_result(work, depth, throughput * params.sky.xyz);
  } else {
    uint m = tri_material(tri);
    bool double_sided = material_double_sided(m);
    vec3 ng = tri_geometric_normal(tri);
    bool front = dot(wi, ng) < 0.0;
    if (front || double_sided) {
      vec3 le = material_emission(m);
      if (max_component(le) > 0.0) {
        float cos_l = abs(dot(wi, ng));
        float pdf_light = tri_area_pdf(tri) * hit.x * hit.x / cos_l;
        add_result(work, depth, throughput * le * (probe_ray ? 1.0 : power_heuristic(pdf_cosine, pdf_light)));
      }
    }
    continues = front || double_sided;
    if (probe_ray) {
      vec3 albedo = continues ? material_albedo(m) : vec3(-1.0);
      uint e = probe_extra_index(work);
      results[e] = albedo.x;
      results[e + 1u] = albedo.y;
      results[e + 2u] = albedo.z;
      if (!(max_component(albedo) > 0.0)) continues = false;
    } else {
      int bounce = kProbeMode ? int(depth) - 1 : int(depth);  // depth of the vertex as the texel estimator counts it
      if (continues && params.max_bounces >= 0 && bounce + 1 > params.max_bounces) continues = false;
      if (continues && bounce + 1 >= params.safety_cap) continues = false;
      if (continues) {
        throughput *= material_albedo(m);
        if (bounce + 1 >= params.rr_start) {
          float survive = min(1.0, max_component(throughput));
          if (!(survive > 0.0) || pcg_uniform(rng) >= survive) continues = false;
          else throughput = throughput / survive;
        } else if (max_component(throughput) <= 0.0) {
          continues = false;
        }
      }
    }
    if (continues) {
      float b1 = hit.z, b2 = hit.w;
      x.geometric_normal = front ? ng : -ng;
      x.position = tri_vertex(tri, 0u) * (1.0 - b1 - b2) + tri_vertex(tri, 1u) * b1 + tri_vertex(tri, 2u) * b2;
      vec3 nv = tri_shading[tri * 6u + 3u].xyz * (1.0 - b1 - b2) + tri_shading[tri * 6u + 4u].xyz * b1 +
                tri_shading[tri * 6u + 5u].xyz * b2;
      float len = length(nv);
      vec3 n = len > 0.0 ? nv / len : vec3(0.0);
      if (!front) n = -n;
      x.shading_normal = dot(n, x.geometric_normal) > 0.05 ? n : x.geometric_normal;
    }
  }
  if (continues) {
    path_depth[p] = depth + 1u;
    uint r = sample_vertex(p, x, throughput, rng);
    path_rng[p] = u64vec2(rng.state, rng.increment);
    if (dispatch_vertex_result(p, r)) return;
  }
  regenerate(p);
}
