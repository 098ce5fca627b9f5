#version 460
#extension GL_GOOGLE_include_directive : require
// Stage "extend": closest hit of every queued continuation ray.
layout(local_size_x = 64) in;
#include "../include/kernel_prelude.glsl"

void main() {
  uint i = gl_GlobalInvocationID.x;
  uint q = out_queue();
  if (i >= counters[kCounterRayQueue0 + q]) return;
  uint p = ray_queue[q * params.path_capacity + i];
  uint steps = 0u;
  path_hit[p] = trace_closest(path_ray_o[p].xyz, path_ray_d[p].xyz, kInfinity, steps);
  if (!kProbeMode) add_auto_cost(path_work[p], 0u, 1u);
  bool primary = path_depth[p] == 0u;
  uint n_primary = subgroupBallotBitCount(subgroupBallot(primary));
  uint n_all = subgroupBallotBitCount(subgroupBallot(true));
  if (subgroupElect()) {
    if (n_primary > 0u) atomicAdd(counters[kCounterRaysPrimary], n_primary);
    if (n_all > n_primary) atomicAdd(counters[kCounterRaysBounce], n_all - n_primary);
  }
  if (params.collect_stats != 0u) {
    uint busy = subgroupAdd(steps), longest = subgroupMax(steps);
    if (subgroupElect()) {
      add_stat64(kCounterStatExtendActive, busy);
      add_stat64(kCounterStatExtendLaunched, longest * gl_SubgroupSize);
    }
  }
}
