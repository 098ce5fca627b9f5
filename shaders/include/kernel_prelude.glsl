// Included first by every wavefront kernel.
#include "common.glsl"
#include "bindings.glsl"
#include "scene_access.glsl"
#include "bvh.glsl"
#include "path.glsl"

uint out_queue() { return push.cur ^ 1u; }

void push_ray(uint p) {
  uint slot = queue_append(kCounterRayQueue0 + out_queue());
  ray_queue[out_queue() * params.path_capacity + slot] = p;
}

void push_shadow(uint p) {
  uint slot = queue_append(kCounterShadowQueue);
  shadow_queue[slot] = p;
}

// After sample_vertex: queue the continuation ray and the shadow rays; a path that ends here
// traces its shadow rays at once (its slot is reused before the connect stage runs).
bool dispatch_vertex_result(uint p, uint r) {
  if ((r & 2u) != 0u) {
    if ((r & 1u) != 0u) {
      push_shadow(p);
    } else {
      uint steps = 0u;
      uint rays = connect_shadow_rays(p, steps);
      atomicAdd(counters[kCounterRaysShadow], rays);
    }
  }
  if ((r & 1u) != 0u) { push_ray(p); return true; }
  return false;
}

#include "bounce_pass.glsl"

// A probe work item (probe, sample) starts with a ray from the probe (path.h probe_ray_direction).
// Depth 0 marks the probe ray (shade: shade_probe_hit; the hit then starts a texel path, its depth
// counted from 1). The direction is kept for the projection (reduce_probes).
void generate_probe_ray(uint p, uint w, uint64_t seed) {
  uint n = params.batch_item_count;
  uint probe = batch_items[params.batch_item_offset + w % n];
  uint sample_index = params.batch_sample_begin + w / n;
  PathSampler rng = path_sampler(seed, kProbeRngStreamBase + uint64_t(probe), sample_index, params.sampler_mode);
  vec3 d = probe_ray_direction(sample_index, params.probe_spp, rng);
  uint e = probe_extra_index(w);
  results[e + 3u] = d.x;
  results[e + 4u] = d.y;
  results[e + 5u] = d.z;
  path_work[p] = w;
  path_depth[p] = 0u;
  path_rng[p] = uvec4(rng.item_hash, rng.index, rng.dimension, rng.mode);
  path_ray_o[p] = vec4(start_points[probe].position.xyz, 0.0);
  path_ray_d[p] = vec4(d, 0.0);
  path_throughput[p] = vec4(1.0, 1.0, 1.0, 0.0);
  push_ray(p);
}

// Generate: claims the next work items (texel, sample) of the batch, live texels in their
// Morton order, until one continues with a ray or the batch's work runs out.
void regenerate(uint p) {
  uint64_t seed = (uint64_t(params.seed_hi) << 32) | uint64_t(params.seed_lo);
  if (kProbeMode) {
    uint w = queue_append(kCounterNextWork);
    if (w >= params.batch_work_total) path_work[p] = kInvalid;
    else generate_probe_ray(p, w, seed);
    return;
  }
  // Bounded: every claim must advance the work counter past this lane's previous claim, so the loop
  // ends within batch_work_total claims; a claim that does not (a lost atomic) is a counted fault.
  uint previous_claim = kInvalid;
  while (true) {
    uint w = queue_append(kCounterNextWork);
    if (previous_claim != kInvalid && w <= previous_claim) {
      atomicAdd(counters[kCounterFaultWorkClaim], 1u);
      path_work[p] = kInvalid;
      return;
    }
    previous_claim = w;
    if (w >= params.batch_work_total) { path_work[p] = kInvalid; return; }
    uint n = params.batch_item_count;
    uint texel = batch_items[params.batch_item_offset + w % n];
    uint sample_index = params.batch_sample_begin + w / n;
    // --guiding auto: each strategy on its own sequence, by its own count (guiding_auto_strategy.h).
    uint64_t stream = uint64_t(texel);
    uint strategy_index = sample_index;
    if ((params.guiding & kGuidingAuto) != 0u) {
      uint word = auto_texel_word(texel);
      bool guided = auto_sample_guided(word, sample_index, guide_words[kGuideAutoPilot]);
      stream = auto_sample_stream(texel, guided);
      strategy_index = auto_strategy_sample_index(word, sample_index, guide_words[kGuideAutoPilot], guided);
    }
    PathSampler rng = path_sampler(seed, stream, strategy_index, params.sampler_mode);
    SurfacePoint x;
    x.position = start_points[texel].position.xyz;
    x.geometric_normal = start_points[texel].geometric_normal.xyz;
    x.shading_normal = start_points[texel].shading_normal.xyz;
    path_work[p] = w;
    path_depth[p] = 0u;
    if ((params.bounce_flags & kBouncePass) != 0u) {
      // Per-bounce layer passes (bounce_pass.glsl): a gather ray, or at layer 0 the direct-light
      // sample below (the same random stream as a path's first vertex).
      if (params.bounce_layer > 0u) {
        if (start_bounce_gather(p, texel, sample_index, x, seed)) return;
        continue;
      }
      path_depth[p] = kBounceDirectRay | kBounceFromTexel;
    }
    uint r = sample_vertex(p, x, vec3(1.0), rng);
    path_rng[p] = uvec4(rng.item_hash, rng.index, rng.dimension, rng.mode);
    if (dispatch_vertex_result(p, r)) return;
  }
}
