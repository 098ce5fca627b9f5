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

// Generate: claims the next work items (texel, sample) of the batch, live texels in their
// Morton order, until one continues with a ray or the batch's work runs out.
void regenerate(uint p) {
  uint64_t seed = (uint64_t(params.seed_hi) << 32) | uint64_t(params.seed_lo);
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
