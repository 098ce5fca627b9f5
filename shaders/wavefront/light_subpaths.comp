#version 460
#extension GL_GOOGLE_include_directive : require
// Stage "light subpaths" (GpuParams::light_subpaths; issue 35): the batch's pool of light-subpath
// vertices (gpu_layout.h kBindingLightSubpaths), before its eye paths start. Three launches, told
// apart by push.mode: kLightSubpathsCount traces each subpath (common/light_subpath_walk.h, the CPU
// pool's walk) and keeps its vertex count; kLightSubpathsOffsets (one workgroup) turns the counts
// into where each subpath's vertices start; kLightSubpathsWrite traces every subpath again, from the
// same random stream, and writes its vertices there. So the pool is in subpath order and the same
// for a seed whatever the device's schedule, at the price of tracing the subpaths twice (a sixteenth
// of a subpath per texel sample: a few percent of the batch's rays). A pool whose vertices would
// pass the binding's capacity is left empty (the batch's eye paths then use the path tracer's
// strategies alone), never cut: a cut would keep the shorter subpaths.
layout(local_size_x = 64) in;
#include "../include/kernel_prelude.glsl"

void store_pool_vertex(uint k, LightVertex v) {
  uint w = kLightPoolVertexWord + k * kLightVertexWords;
  uvec4 a = floatBitsToUint(v.position_depth), b = floatBitsToUint(v.geometric_normal_layer);
  uvec4 c = floatBitsToUint(v.shading_normal_ratio), d = floatBitsToUint(v.weight_a), e = floatBitsToUint(v.b);
  for (uint i = 0u; i < 4u; ++i) {
    light_pool[w + i] = a[i];
    light_pool[w + 4u + i] = b[i];
    light_pool[w + 8u + i] = c[i];
    light_pool[w + 12u + i] = d[i];
    light_pool[w + 16u + i] = e[i];
  }
}

// Subpath i's vertices (written from pool vertex `first` when `write`); returns how many it keeps.
uint trace_subpath(uint i, bool write, uint first) {
  uint64_t seed = (uint64_t(params.seed_hi) << 32) | uint64_t(params.seed_lo);
  // The pass's first sample keys the pool's streams (the CPU keys each pass's pool so).
  PathSampler rng = path_sampler(seed, kLightSubpathStreamBase + uint64_t(i), params.batch_sample_begin, params.sampler_mode);
  vec4 sphere = params.light_subpath_sphere;
  LightSubpathWalk w = light_subpath_begin(light_subpath_start_of_params(), sphere.xyz, sphere.w, params.punctual_layers, rng);
  uint kept = 0u, rays = 0u, steps = 0u;
  while (w.valid) {
    ++rays;
    vec4 hit = trace_closest(w.origin, w.direction, kInfinity, steps);
    uint tri = floatBitsToUint(hit.y);
    if (tri == kInvalid) break;
    SurfacePoint y;
    if (!light_subpath_surface(w, tri, hit.z, hit.w, y)) break;  // single-sided back faces absorb
    // NEE's density of the start from the first hit, with the strategy an eye vertex there uses
    // (emitter guiding's learned mixture where its record samples it, as the CPU's pool takes
    // EmitterGuidingCache::vertex_site; none on probes' pools, whose NEE is unguided).
    float nee = w.depth == 1u ? light_subpath_nee_density(w, y, emitter_guide_without_learning(y.position, y.shading_normal)) : 0.0;
    LightVertex v;
    vec3 albedo;
    if (!light_subpath_vertex(w, tri, hit.x, hit.z, hit.w, y, nee, v, albedo)) break;
    if (light_vertex_finite(v)) {
      if (write && first + kept < params.light_subpath_capacity) store_pool_vertex(first + kept, v);
      ++kept;
    }
    if (!light_subpath_continue(w, v, y, albedo, params.light_subpath_depth, params.rr_start, rng)) break;
  }
  uint total = subgroupAdd(rays);
  if (subgroupElect()) atomicAdd(counters[kCounterRaysLightSubpaths], total);
  return kept;
}

shared uint partial_sums[64];

void prefix_sums() {
  uint n = params.light_subpaths;
  uint t = gl_LocalInvocationID.x;
  uint per = (n + 63u) / 64u;
  uint begin = min(n, t * per), end = min(n, begin + per);
  uint sum = 0u;
  for (uint i = begin; i < end; ++i) sum += light_pool[kLightPoolCounts + i];
  partial_sums[t] = sum;
  barrier();
  if (t == 0u) {
    uint run = 0u;
    for (uint k = 0u; k < 64u; ++k) {
      uint s = partial_sums[k];
      partial_sums[k] = run;
      run += s;
    }
    bool fits = run <= params.light_subpath_capacity;
    light_pool[kLightPoolVertices] = fits ? run : 0u;
    light_pool[kLightPoolPaths] = fits && run > 0u ? n : 0u;
    counters[kCounterLightSubpaths] = fits && run > 0u ? n : 0u;
    counters[kCounterLightSubpathVertices] = run;  // what the pool needed: the host grows the binding past it
  }
  barrier();
  uint run = partial_sums[t];
  for (uint i = begin; i < end; ++i) {
    uint count = light_pool[kLightPoolCounts + i];
    light_pool[kLightPoolCounts + i] = run;
    run += count;
  }
}

void main() {
  if (params.light_subpaths == 0u) return;
  if (push.mode == kLightSubpathsOffsets) {
    prefix_sums();
    return;
  }
  uint i = gl_GlobalInvocationID.x;
  if (i >= params.light_subpaths) return;
  if (push.mode == kLightSubpathsCount) {
    light_pool[kLightPoolCounts + i] = trace_subpath(i, false, 0u);
  } else if (light_pool[kLightPoolPaths] > 0u) {
    trace_subpath(i, true, light_pool[kLightPoolCounts + i]);
  }
}
