// The per-bounce mode's layer passes on the wavefront (issue 10; the host side is
// runtime/src/core/per_bounce_bake.cpp, the CPU estimator runtime/src/cpu/cpu_bounce_integrator.cpp,
// whose meaning this follows sample for sample). A layer-k sample is a short path:
// - k = 0: next-event estimation at the texel and its continuation ray, whose hit adds only its
//   MIS-weighted emission or sky (the path tracer cut at direct light);
// - k >= 1: a cosine ray from the texel; its hit y adds albedo(y) B_{k-1}(y) from the cache of layer
//   k - 1; where y has no lit texel (the back of a double-sided surface, a triangle without texels)
//   B_{k-1}(y) is estimated on the fly: one more gather ray from y reading layer k - 2, ..., down to
//   a direct-light sample at layer 0 (also taken at layer 0 with kBounceTraceFirst).
// Path state: path_depth holds the layer the gather ray's hit reads, or kBounceDirectRay for the
// continuation ray of a direct-light sample (kBounceFromTexel: the texel's own, whose single-sided
// back faces are flagged for the host's inside-geometry test). Every contribution goes to result
// slot 0 (recorded = 0), so next-event estimation and connect are reused unchanged.
#include "exitance/common/bounce_gather.h"

const uint kBounceDirectRay = 0x80000000u;
const uint kBounceFromTexel = 0x40000000u;

uint bounce_cache_word(uint i) { return floatBitsToUint(bounce_cache[i]); }

// BounceLayerCache::lookup on the device: B_layer at barycentrics (b1, b2) of triangle `tri`, hit at
// `position` on the side `normal`: the bilinear mean of the footprint's lit texels on the same
// surface, renormalised over them; false when there is none or the triangle has no page.
bool bounce_cache_lookup(uint layer, uint tri, float b1, float b2, vec3 position, vec3 normal, out vec3 value) {
  value = vec3(0.0);
  if (tri >= bounce_cache_word(kBounceCacheTriangles + 1u)) return false;
  uint t = bounce_cache_word(kBounceCacheTriangles) + tri * kBounceCacheTriangleWords;
  uint instance = bounce_cache_word(t);
  if (instance >= bounce_cache_word(kBounceCacheInstances + 1u)) return false;
  float b0 = 1.0 - b1 - b2;
  vec2 uv = vec2(bounce_cache[t + 1u], bounce_cache[t + 2u]) * b0 + vec2(bounce_cache[t + 3u], bounce_cache[t + 4u]) * b1 +
            vec2(bounce_cache[t + 5u], bounce_cache[t + 6u]) * b2;
  uint r = bounce_cache_word(kBounceCacheInstances) + instance * kBounceCacheInstanceWords;
  int page = int(bounce_cache_word(r));
  if (page < 0 || uint(page) >= bounce_cache_word(kBounceCachePages + 1u)) return false;
  vec4 scale_offset = vec4(bounce_cache[r + 1u], bounce_cache[r + 2u], bounce_cache[r + 3u], bounce_cache[r + 4u]);
  uint g = bounce_cache_word(kBounceCachePages) + uint(page) * kBounceCachePageWords;
  int width = int(bounce_cache_word(g)), height = int(bounce_cache_word(g + 1u));
  uint first_texel = bounce_cache_word(g + 2u);
  uint layer_words = bounce_cache_word(kBounceCacheLayers) + layer * bounce_cache_word(kBounceCacheLayers + 1u);
  BilinearFootprint f = bilinear_footprint(lightmap_page_uv(uv, scale_offset), width, height);
  float weight = 0.0;
  vec3 sum = vec3(0.0);
  for (int dy = 0; dy <= 1; ++dy)
    for (int dx = 0; dx <= 1; ++dx) {
      int x = f.x0 + dx, y = f.y0 + dy;
      if (x < 0 || y < 0 || x >= width || y >= height) continue;
      uint at = layer_words + (first_texel + uint(y) * uint(width) + uint(x)) * kBounceCacheTexelWords;
      if (!(bounce_cache[at + 3u] > 0.0)) continue;
      vec3 n = vec3(bounce_cache[at + 7u], bounce_cache[at + 8u], bounce_cache[at + 9u]);
      vec3 p = vec3(bounce_cache[at + 4u], bounce_cache[at + 5u], bounce_cache[at + 6u]);
      if (!texel_on_hit_surface(p, n, position, normal)) continue;
      float w = bilinear_weight(f, dx, dy);
      weight += w;
      sum += w * vec3(bounce_cache[at], bounce_cache[at + 1u], bounce_cache[at + 2u]);
    }
  if (!(weight > kLeastFootprintWeight)) return false;
  value = sum / weight;
  return true;
}

void store_rng(uint p, PathSampler rng) { path_rng[p] = uvec4(rng.item_hash, rng.index, rng.dimension, rng.mode); }

// A gather ray from x whose hit reads `layer`, carrying `throughput`; false when the sampled
// direction is unusable (the sample adds 0).
bool start_gather_ray(uint p, SurfacePoint x, vec3 throughput, uint layer, inout PathSampler rng) {
  DirectionSample d = sample_continuation(params.sampling_strategy, x, rng);
  if (!(d.pdf > 0.0)) return false;
  // cos / (pi pdf): 1 for cosine sampling; kept so another strategy stays unbiased.
  float weight = max(dot(x.shading_normal, d.direction), 0.0) * kInvPi / d.pdf;
  path_ray_o[p] = vec4(offset_ray_origin(x.position, x.geometric_normal, params.scene_extent), 0.0);
  path_ray_d[p] = vec4(d.direction, 0.0);
  path_throughput[p] = vec4(throughput * weight, d.pdf);
  path_depth[p] = layer;
  push_ray(p);
  return true;
}

// Generate, layers k >= 1: the gather ray of sample `sample_index` at `texel` (point x). True when a
// ray was queued. (Layer 0 starts as a path does: kernel_prelude.glsl regenerate.)
bool start_bounce_gather(uint p, uint texel, uint sample_index, SurfacePoint x, uint64_t seed) {
  uint k = params.bounce_layer;
  PathSampler rng = path_sampler(seed, kBounceRngStreamBase * uint64_t(k) + uint64_t(texel), sample_index, params.sampler_mode);
  bool queued = start_gather_ray(p, x, vec3(1.0), k - 1u, rng);
  store_rng(p, rng);
  return queued;
}

// What the hit of a layer pass's ray leaves to do.
struct BounceHit {
  bool queued;         // a gather ray from the hit was queued
  bool direct_sample;  // a direct-light sample at `next` with `throughput` (the shade stage's sample_vertex)
  SurfacePoint next;
  vec3 throughput;
};

// Shade: the hit of path p's ray in state `state` (path_depth). Kept free of next-event estimation
// (the caller's one sample_vertex takes the direct-light sample): LLVM's compile time on lavapipe
// grows fast with each inlined copy of it.
BounceHit shade_bounce_hit(uint p, uint work, uint state, vec4 hit, vec3 wi, vec4 tp, inout PathSampler rng) {
  BounceHit r;
  r.queued = false;
  r.direct_sample = false;
  uint tri = floatBitsToUint(hit.y);
  vec3 throughput = tp.xyz;
  if ((state & kBounceDirectRay) != 0u) {
    if (tri == kInvalid) {
      add_result(work, 0u, throughput * escaped_radiance(wi, tp.w));
      return r;
    }
    if ((state & kBounceFromTexel) != 0u && !(dot(wi, triangle_geometric_normal(tri)) < 0.0) &&
        !material_double_sided(scene_material(scene_triangle_material(tri))))
      results[bounce_back_face_index(work)] = 1.0;
    PathLimits direct_only;
    direct_only.max_bounces = 0;
    direct_only.rr_start = params.rr_start;
    direct_only.safety_cap = params.safety_cap;
    // Emitter guiding: the MIS weight reads the density of the mixture the direct sample's vertex used.
    HitResult h = shade_continuation_hit(tri, hit.x, hit.z, hit.w, wi, tp.w, throughput, 0, direct_only, emitter_guide_of_path(p), rng);
    if (h.radiance != vec3(0.0)) add_result(work, 0u, h.radiance);
    return r;
  }
  if (tri == kInvalid) return r;  // a miss adds 0: the sky is direct light, in B_0
  count_in_subgroup(kCounterBounceGathers);
  vec3 ng = triangle_geometric_normal(tri);
  bool front = dot(wi, ng) < 0.0;
  if (!front && !material_double_sided(scene_material(scene_triangle_material(tri)))) {
    count_in_subgroup(kCounterBounceBackFaces);  // absorbs, as in path mode
    return r;
  }
  vec3 albedo = scene_albedo(tri, hit.z, hit.w);
  if (!(max_component(albedo) > 0.0)) return r;
  SurfacePoint y = surface_point_on_triangle(tri, ng, hit.z, hit.w, front);
  uint layer = state;
  bool traced_first = layer == 0u && (params.bounce_flags & kBounceTraceFirst) != 0u;
  if (!traced_first) {
    vec3 b;
    if (front && bounce_cache_lookup(layer, tri, hit.z, hit.w, y.position, ng, b)) {
      add_result(work, 0u, throughput * albedo * b);
      return r;
    }
    count_in_subgroup(kCounterBounceTexelless);
  }
  if (layer == 0u) {
    r.direct_sample = true;
    r.next = y;
    r.throughput = throughput * albedo;
  } else {
    r.queued = start_gather_ray(p, y, throughput * albedo, layer - 1u, rng);
  }
  return r;
}
