// Included first by every wavefront kernel.
#include "common.glsl"
#include "bindings.glsl"
#include "rng.glsl"
#include "sampling.glsl"
#include "ray_offset.glsl"
#include "bvh.glsl"
#include "scene.glsl"
#include "path.glsl"

uint out_queue() { return push.cur ^ 1u; }

void push_ray(uint p) {
  uint slot = queue_append(kRayCount0 + out_queue());
  ray_queue[out_queue() * params.path_capacity + slot] = p;
}

void push_shadow(uint p) {
  uint slot = queue_append(kShadowCount);
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
      atomicAdd(counters[kRaysShadow], rays);
    }
  }
  if ((r & 1u) != 0u) { push_ray(p); return true; }
  return false;
}

// cpu_reference_integrator.h: kProbeRngStreamBase, kProbeStratifiedSetSize.
const uint64_t kProbeRngStreamBase = 1ul << 40;
const uint kProbeStratifiedSetSize = 256u;

// A probe work item (probe, sample) starts with a ray from the probe (no surface, so no next-event
// estimation) in its stratified sphere direction, drawn as the reference does: Pcg32(seed,
// kProbeRngStreamBase + probe, sample), u1 then u2, sets of kProbeStratifiedSetSize samples from 0.
// Depth 0 marks the probe ray (shade: emission at full weight; the hit then starts a texel path,
// its depth counted from 1). The direction is kept for the projection (reduce_probes).
void generate_probe_ray(uint p, uint w, uint64_t seed) {
  uint n = params.batch_texel_count;
  uint probe = batch_texels[params.batch_texel_offset + w % n];
  uint sample_index = params.batch_sample_begin + w / n;
  Pcg32 rng = pcg_init(seed, kProbeRngStreamBase + uint64_t(probe), uint64_t(sample_index));
  float u1 = pcg_uniform(rng);
  float u2 = pcg_uniform(rng);
  uint set_begin = sample_index - sample_index % kProbeStratifiedSetSize;
  uint set_count = min(kProbeStratifiedSetSize, params.probe_spp - set_begin);
  vec3 d = probe_direction(sample_index - set_begin, set_count, u1, u2);
  uint e = probe_extra_index(w);
  results[e + 3u] = d.x;
  results[e + 4u] = d.y;
  results[e + 5u] = d.z;
  path_work[p] = w;
  path_depth[p] = 0u;
  path_rng[p] = u64vec2(rng.state, rng.increment);
  path_ray_o[p] = vec4(texels[probe * 3u].xyz, 0.0);
  path_ray_d[p] = vec4(d, 0.0);
  path_throughput[p] = vec4(1.0, 1.0, 1.0, 0.0);
  push_ray(p);
}

// Generate: claims the next work items (texel, sample) of the batch, live texels in their
// Morton order, until one continues with a ray or the batch's work runs out.
void regenerate(uint p) {
  uint64_t seed = (uint64_t(params.seed_hi) << 32) | uint64_t(params.seed_lo);
  if (kProbeMode) {
    uint w = queue_append(kNextWork);
    if (w >= params.batch_work_total) path_work[p] = kInvalid;
    else generate_probe_ray(p, w, seed);
    return;
  }
  while (true) {
    uint w = queue_append(kNextWork);
    if (w >= params.batch_work_total) { path_work[p] = kInvalid; return; }
    uint n = params.batch_texel_count;
    uint texel = batch_texels[params.batch_texel_offset + w % n];
    uint sample_index = params.batch_sample_begin + w / n;
    Pcg32 rng = pcg_init(seed, uint64_t(texel), uint64_t(sample_index));
    SurfacePoint x;
    x.position = texels[texel * 3u].xyz;
    x.geometric_normal = texels[texel * 3u + 1u].xyz;
    x.shading_normal = texels[texel * 3u + 2u].xyz;
    path_work[p] = w;
    path_depth[p] = 0u;
    uint r = sample_vertex(p, x, vec3(1.0), rng);
    path_rng[p] = u64vec2(rng.state, rng.increment);
    if (dispatch_vertex_result(p, r)) return;
  }
}
