#version 460
#extension GL_GOOGLE_include_directive : require
// Stage "connect": shadow rays (any hit) of next-event estimation; unoccluded ones add their
// contribution to the path's work item (one writer: the path's own slot).
layout(local_size_x = 64) in;
#include "../include/kernel_prelude.glsl"

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= counters[kCounterShadowQueue]) return;
  uint p = shadow_queue[i];
  uint steps = 0u;
  uint rays = connect_shadow_rays(p, steps);
  uint total = subgroupAdd(rays);
  if (subgroupElect()) atomicAdd(counters[kCounterRaysShadow], total);
  if (params.collect_stats != 0u) {
    uint busy = subgroupAdd(steps), longest = subgroupMax(steps);
    if (subgroupElect()) {
      add_stat64(kCounterStatConnectActive, busy);
      add_stat64(kCounterStatConnectLaunched, longest * gl_SubgroupSize);
    }
  }
}
