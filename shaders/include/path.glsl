// The path tracer's per-vertex steps, in the reference's order (cpu_reference_integrator.cpp,
// Impl::trace and Impl::next_event), including the order of random numbers, so one (seed, texel,
// sample) gives the same path on both backends up to floating-point rounding.

struct SurfacePoint { vec3 position; vec3 geometric_normal; vec3 shading_normal; };

// Writes the path's two shadow rays (area light, punctual light) with their unoccluded
// contributions (throughput included). Returns true when at least one ray needs tracing.
bool next_event(uint p, SurfacePoint x, vec3 origin, vec3 throughput, inout Pcg32 rng) {
  vec4 area_ray = vec4(0.0), area_contrib = vec4(0.0), punct_ray = vec4(0.0), punct_contrib = vec4(0.0);
  if (params.emitter_count > 0u) {
    float uc = pcg_uniform(rng), u1 = pcg_uniform(rng), u2 = pcg_uniform(rng);
    uint tri = emitter_tris[sample_cdf_emitters(uc, params.emitter_count)];
    vec2 bary = sample_triangle_barycentrics(u1, u2);
    vec3 p0 = tri_vertex(tri, 0u), p1 = tri_vertex(tri, 1u), p2 = tri_vertex(tri, 2u);
    vec3 light_position = p0 * (1.0 - bary.x - bary.y) + p1 * bary.x + p2 * bary.y;
    vec3 light_normal = normalize(cross(p1 - p0, p2 - p0));
    float pdf_area = tri_area_pdf(tri);
    vec3 to_light = light_position - x.position;
    float distance2 = dot(to_light, to_light);
    float distance = sqrt(distance2);
    if (distance > 0.0) {
      vec3 wi = to_light / distance;
      float cos_x = dot(x.shading_normal, wi);
      float cos_l = -dot(light_normal, wi);
      uint m = tri_material(tri);
      if (material_double_sided(m)) cos_l = abs(cos_l);
      if (cos_x > 0.0 && dot(x.geometric_normal, wi) > 0.0 && cos_l > 0.0) {
        vec3 toward_x = dot(light_normal, wi) < 0.0 ? light_normal : -light_normal;
        vec3 target = offset_ray_origin(light_position, toward_x, params.scene_extent);
        vec3 span = target - origin;
        float span_length = length(span);
        if (span_length > 0.0) {
          float pdf_light = pdf_area * distance2 / cos_l;
          float pdf_cosine = cos_x * kInvPi;
          float weight = power_heuristic(pdf_light, pdf_cosine);
          vec3 le = material_emission(m);
          area_ray = vec4(span / span_length, span_length);
          area_contrib = vec4(throughput * (le * (cos_x * kInvPi * weight / pdf_light)), 1.0);
        } else {
          area_contrib = vec4(0.0, 0.0, 0.0, 2.0);  // counted as traced (the reference counts it), nothing to add
        }
      }
    }
  }
  if (params.punctual_count > 0u) {
    float probability;
    uint li = sample_cdf_punctual(pcg_uniform(rng), params.punctual_count, probability);
    vec4 a = punctual[li * 3u], b = punctual[li * 3u + 1u], c = punctual[li * 3u + 2u];
    uint type = floatBitsToUint(a.w);
    vec3 wi;
    float distance = kInfinity;
    float falloff = 1.0;
    if (type == 2u) {
      wi = -b.xyz;
    } else {
      vec3 to_light = a.xyz - x.position;
      distance = length(to_light);
      wi = to_light / distance;
      falloff = 1.0 / (distance * distance);
      if (type == 1u) falloff *= spot_attenuation(b.xyz, b.w, c.w, -wi);
    }
    float cos_x = dot(x.shading_normal, wi);
    if (distance > 0.0 && falloff > 0.0 && cos_x > 0.0 && dot(x.geometric_normal, wi) > 0.0 && probability > 0.0) {
      punct_ray = vec4(wi, distance);
      punct_contrib = vec4(throughput * (c.xyz * (falloff * cos_x * kInvPi / probability)), 1.0);
    }
  }
  shadow_rays[p * 4u + 0u] = area_ray;
  shadow_rays[p * 4u + 1u] = area_contrib;
  shadow_rays[p * 4u + 2u] = punct_ray;
  shadow_rays[p * 4u + 3u] = punct_contrib;
  return area_contrib.w != 0.0 || punct_contrib.w != 0.0;
}

// Traces path p's pending shadow rays and adds what they carry to its work item (connect stage,
// and inline for a path that ends right after next-event estimation). Returns rays traced.
uint connect_shadow_rays(uint p, inout uint steps) {
  uint work = path_work[p], depth = path_depth[p];
  vec3 origin = path_ray_o[p].xyz;
  uint rays = 0u;
  for (uint k = 0u; k < 2u; ++k) {
    vec4 contrib = shadow_rays[p * 4u + 2u * k + 1u];
    if (contrib.w == 0.0) continue;
    ++rays;
    if (contrib.w != 1.0) continue;
    vec4 ray = shadow_rays[p * 4u + 2u * k];
    if (!trace_any(origin, ray.xyz, ray.w, steps)) add_result(work, depth, contrib.xyz);
    shadow_rays[p * 4u + 2u * k + 1u] = vec4(0.0);
  }
  return rays;
}

// At surface point x of path p (state: work, depth, throughput, rng): next-event estimation, then
// the cosine-sampled continuation. Returns 0 when the path ends here, 1 when it continues with a
// ray; bit 1 set when shadow rays are pending.
uint sample_vertex(uint p, SurfacePoint x, vec3 throughput, inout Pcg32 rng) {
  vec3 origin = offset_ray_origin(x.position, x.geometric_normal, params.scene_extent);
  path_ray_o[p] = vec4(origin, 0.0);
  bool shadows = next_event(p, x, origin, throughput, rng);
  // The reference calls sample_cosine_hemisphere(rng.uniform(), rng.uniform()): C++ leaves the order of
  // argument evaluation unspecified and GCC evaluates right to left, so u2 is drawn first there. Either
  // order is the same estimator; mirroring GCC makes paths match the reference sample for sample.
  float u2 = pcg_uniform(rng);
  float u1 = pcg_uniform(rng);
  vec3 local = sample_cosine_hemisphere(u1, u2);
  vec3 wi = to_world(local, x.shading_normal);
  float cos_g = dot(wi, x.geometric_normal);
  uint pending = shadows ? 2u : 0u;
  if (!(cos_g > 0.0) || local.z <= 0.0) return pending;
  path_ray_d[p] = vec4(wi, 0.0);
  path_throughput[p] = vec4(throughput, local.z * kInvPi);
  return pending | 1u;
}
