#version 460
#extension GL_GOOGLE_include_directive : require
// Stage "accumulate" of probe batches: per probe of the batch, in sample order (one writer per
// probe), the incident radiance of each sample, L = (sky or emission met by the probe ray) +
// albedo of the hit x (E/pi estimate at the hit), 0 on a back face (counted), projected onto the
// L2 SH basis with weight 4 pi into double sums (runtime/src/cpu/cpu_reference_integrator.cpp, bake_probes).
layout(local_size_x = 64) in;
#include "../include/kernel_prelude.glsl"

#include "exitance/common/spherical_harmonics_basis.h"

void main() {
  uint j = gl_GlobalInvocationID.x;
  uint n = params.batch_item_count;
  if (j >= n) return;
  uint probe = batch_items[params.batch_item_offset + j];
  const double weight = double(kShSphereMeasure);
  double sums[27];
  for (uint i = 0u; i < 27u; ++i) sums[i] = acc_probe_sh[probe * 27u + i];
  uint nonfinite = 0u, samples = 0u, back_faces = 0u;
  for (uint s = 0u; s < params.batch_sample_count; ++s) {
    uint w = s * n + j;
    uint r0 = result_index(w, 0u), r1 = result_index(w, 1u), e = probe_extra_index(w);
    vec3 albedo = vec3(results[e], results[e + 1u], results[e + 2u]);
    vec3 radiance = vec3(0.0);
    if (albedo.x < 0.0) {
      ++back_faces;
    } else {
      vec3 at_hit = vec3(results[r1], results[r1 + 1u], results[r1 + 2u]);
      radiance = vec3(results[r0], results[r0 + 1u], results[r0 + 2u]) + albedo * at_hit;
    }
    if (any(isnan(radiance)) || any(isinf(radiance))) { ++nonfinite; continue; }
    float y[9];
    sh_basis(vec3(results[e + 3u], results[e + 4u], results[e + 5u]), y);
    for (uint k = 0u; k < 9u; ++k)
      for (uint c = 0u; c < 3u; ++c) sums[k * 3u + c] += double(radiance[c]) * double(y[k]) * weight;
    ++samples;
  }
  for (uint i = 0u; i < 27u; ++i) acc_probe_sh[probe * 27u + i] = sums[i];
  acc_probe_counts[probe * 2u] += samples;
  acc_probe_counts[probe * 2u + 1u] += back_faces;
  if (nonfinite > 0u) atomicAdd(counters[kCounterNonfinite], nonfinite);
}
