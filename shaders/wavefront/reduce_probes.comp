#version 460
#extension GL_GOOGLE_include_directive : require
// Stage "accumulate" of probe batches: per probe of the batch, in sample order (one writer per
// probe), the incident radiance of each sample, L = (sky or emission met by the probe ray) +
// albedo of the hit x (E/pi estimate at the hit), 0 on a back face (counted), projected onto the
// L2 SH basis with weight 4 pi into double sums (runtime/src/cpu/cpu_reference_integrator.cpp, bake_probes).
// Also per probe the squares of each sample's L0 term (rgb; the probe's error estimate) and, with
// params.light_layers (the runtime's refreshed probes, vulkan/probe_refresh.h), each light layer's
// part of the radiance projected the same way: slot 0's radiance goes to the layer of what the probe
// ray met, the path at the hit's light layers (bindings.glsl light_result_index) times the albedo, so
// the layers sum to the sample's radiance. Layout: bindings.glsl acc_probe_sh.
layout(local_size_x = 64) in;
#include "../include/kernel_prelude.glsl"

#include "exitance/common/spherical_harmonics_basis.h"

// The light layers' part, layer l of the batch's probe j: its own thread (one per probe and layer),
// so a probe's layers cost no more time than its totals.
void reduce_light_layer(uint j, uint l) {
  uint n = params.batch_item_count;
  uint probe = batch_items[params.batch_item_offset + j];
  const double weight = double(kShSphereMeasure);
  uint probes = params.item_count_total;
  uint at = probes * 30u + (l * probes + probe) * 27u;
  double sums[27];
  for (uint i = 0u; i < 27u; ++i) sums[i] = acc_probe_sh[at + i];
  for (uint s = 0u; s < params.batch_sample_count; ++s) {
    uint w = s * n + j;
    uint r0 = result_index(w, 0u), r1 = result_index(w, 1u), e = probe_extra_index(w);
    vec3 albedo = vec3(results[e], results[e + 1u], results[e + 2u]);
    if (albedo.x < 0.0) continue;  // a back face adds 0
    uint light = light_result_index(w, l);
    vec3 radiance = albedo * vec3(results[light], results[light + 1u], results[light + 2u]);
    uint met = uint(results[e + 6u]);
    if (met > 0u && min(met - 1u, params.light_layers - 1u) == l) radiance += vec3(results[r0], results[r0 + 1u], results[r0 + 2u]);
    if (radiance == vec3(0.0)) continue;
    // The samples the totals leave out (non-finite) are left out here too.
    vec3 total = vec3(results[r0], results[r0 + 1u], results[r0 + 2u]) + albedo * vec3(results[r1], results[r1 + 1u], results[r1 + 2u]);
    if (any(isnan(total)) || any(isinf(total))) continue;
    float y[9];
    sh_basis(vec3(results[e + 3u], results[e + 4u], results[e + 5u]), y);
    for (uint k = 0u; k < 9u; ++k)
      for (uint c = 0u; c < 3u; ++c) sums[k * 3u + c] += double(radiance[c]) * double(y[k]) * weight;
  }
  for (uint i = 0u; i < 27u; ++i) acc_probe_sh[at + i] = sums[i];
}

// Thread (j, slot), j the batch's probe: slot 0 its totals, squares and counts, slot l + 1 its light
// layer l (params.light_layers of them).
void main() {
  uint n = params.batch_item_count;
  uint j = gl_GlobalInvocationID.x % n;
  uint slot = gl_GlobalInvocationID.x / n;
  if (slot > params.light_layers) return;
  if (slot > 0u) {
    reduce_light_layer(j, slot - 1u);
    return;
  }
  uint probe = batch_items[params.batch_item_offset + j];
  const double weight = double(kShSphereMeasure);
  uint probes = params.item_count_total;
  double sums[27];
  for (uint i = 0u; i < 27u; ++i) sums[i] = acc_probe_sh[probe * 27u + i];
  dvec3 squares = dvec3(0.0lf);
  uint squares_at = probes * 27u + probe * 3u;
  for (uint c = 0u; c < 3u; ++c) squares[c] = acc_probe_sh[squares_at + c];
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
    for (uint c = 0u; c < 3u; ++c) {
      double l0 = double(radiance[c]) * double(y[0]) * weight;
      squares[c] += l0 * l0;
    }
    ++samples;
  }
  for (uint i = 0u; i < 27u; ++i) acc_probe_sh[probe * 27u + i] = sums[i];
  for (uint c = 0u; c < 3u; ++c) acc_probe_sh[squares_at + c] = squares[c];
  acc_probe_counts[probe * 2u] += samples;
  acc_probe_counts[probe * 2u + 1u] += back_faces;
  if (nonfinite > 0u) atomicAdd(counters[kCounterNonfinite], nonfinite);
}
