#version 460
#extension GL_GOOGLE_include_directive : require
// Traversal only: incoherent closest-hit rays, origins uniform in the scene bounds, directions
// uniform on the sphere. Counts hits so the traversal cannot be optimised away.
layout(local_size_x = 64) in;
#include "../include/kernel_prelude.glsl"

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= params.batch_work_total) return;
  Pcg32 rng = pcg_init(uint64_t(params.seed_lo), uint64_t(i), 0ul);
  vec3 lo = params.bench_lo.xyz, hi = params.bench_hi.xyz;
  vec3 o = lo + (hi - lo) * vec3(pcg_uniform(rng), pcg_uniform(rng), pcg_uniform(rng));
  float z = 1.0 - 2.0 * pcg_uniform(rng);
  float r = sqrt(max(0.0, 1.0 - z * z));
  float phi = 2.0 * kPi * pcg_uniform(rng);
  vec3 d = vec3(r * cos(phi), r * sin(phi), z);
  uint steps = 0u;
  vec4 hit = trace_closest(o, d, kInfinity, steps);
  bool found = floatBitsToUint(hit.y) != kInvalid;
  uint hits = subgroupBallotBitCount(subgroupBallot(found));
  if (subgroupElect()) atomicAdd(counters[kCounterRaysPrimary], hits);
  if (params.collect_stats != 0u) {
    uint busy = subgroupAdd(steps), longest = subgroupMax(steps);
    if (subgroupElect()) {
      add_stat64(kCounterStatExtendActive, busy);
      add_stat64(kCounterStatExtendLaunched, longest * gl_SubgroupSize);
    }
  }
}
