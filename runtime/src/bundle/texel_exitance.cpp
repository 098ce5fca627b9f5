#include "exitance/runtime/bundle/texel_exitance.h"

#include <algorithm>
#include <cmath>

#include "exitance/common/sampling.h"
#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance/runtime/material_eval.h"
#include "exitance/runtime/svo_exitance.h"

namespace exitance {
namespace {

// Barycentrics (b1, b2) of p's projection onto triangle t.
void barycentrics_on_triangle(const Scene& scene, uint32_t t, Vec3 p, float& b1, float& b2) {
  const Vec3* v = &scene.positions[size_t(t) * 3];
  const Vec3 e1 = v[1] - v[0], e2 = v[2] - v[0], d = p - v[0];
  const float d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2), d1 = dot(d, e1), d2 = dot(d, e2);
  const float det = d11 * d22 - d12 * d12;
  b1 = b2 = 1.0f / 3.0f;
  if (!(std::fabs(det) > 0)) return;
  b1 = std::clamp((d22 * d1 - d12 * d2) / det, 0.0f, 1.0f);
  b2 = std::clamp((d11 * d2 - d12 * d1) / det, 0.0f, 1.0f - b1);
}

}  // namespace

void fill_svo_exitance(formats::SparseVoxelOctree& svo, const Scene& scene, const TexelGBuffer& gbuffer,
                       const LightmapEstimate& estimate) {
  SvoExitanceCache cache(svo);
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    const LiveTexel& t = gbuffer.texels[i];
    if (estimate.texels[i].samples == 0) continue;
    float b1, b2;
    barycentrics_on_triangle(scene, t.triangle, t.position, b1, b2);
    const Vec3 outgoing = emitted_radiance(scene, t.triangle, b1, b2) + t.albedo * estimate.mean_total(i);
    cache.deposit({t.position, t.geometric_normal, outgoing * kPi, t.world_texel_size * t.world_texel_size});
  }
  cache.publish(1.0f);
  cache.store_into(svo);
}

VoxelDeposits voxel_deposits(const formats::SparseVoxelOctree& svo, const Scene& scene, const TexelGBuffer& gbuffer) {
  VoxelDeposits d;
  const size_t nodes = svo.nodes.size();
  std::vector<Vec3> normals(nodes);
  for (size_t i = 0; i < nodes; ++i) {
    const std::array<float, 3> n = formats::decode_octahedral_normal(svo.nodes[i].normal_oct);
    normals[i] = {n[0], n[1], n[2]};
  }
  d.flipped.assign(nodes, 0);
  for (size_t i = 1; i < nodes; ++i) d.flipped[i] = dot(normals[i], normals[svo.nodes[i].parent]) < 0 ? 1 : 0;
  // As SvoExitanceCache::deposit places a sample: the leaf holding the position, the side its normal
  // faces. Found on all cores (a million texels' tree descents after each geometry edit), counted
  // and placed in G-buffer order on one, the entries filled on all cores again.
  const size_t texels = gbuffer.texels.size();
  std::vector<uint32_t> side_of(texels, UINT32_MAX);
  for_each_chunk(texels, [&](size_t first, size_t last) {
    for (size_t i = first; i < last; ++i) {
      const LiveTexel& t = gbuffer.texels[i];
      const uint32_t node = formats::svo_find_node(svo, {t.position.x, t.position.y, t.position.z}, svo.depth);
      if (node == formats::kSvoNoParent || svo.nodes[node].level != svo.depth) continue;
      side_of[i] = 2 * node + (dot(t.geometric_normal, normals[node]) >= 0 ? 0u : 1u);
    }
  }, 16384);
  std::vector<uint32_t> count(2 * nodes + 1, 0);
  for (uint32_t side : side_of)
    if (side != UINT32_MAX) ++count[side + 1];
  d.side_first.assign(2 * nodes + 1, 0);
  for (size_t s = 0; s < 2 * nodes; ++s) d.side_first[s + 1] = d.side_first[s] + count[s + 1];
  const size_t entries = d.side_first.back();
  d.texel.resize(entries), d.weight.resize(entries), d.emitted.resize(entries), d.albedo.resize(entries);
  std::vector<uint32_t> next(d.side_first.begin(), d.side_first.end() - 1);
  std::vector<uint32_t>& entry_of = side_of;  // each texel's entry, in place of its side
  for (uint32_t& side : entry_of)
    if (side != UINT32_MAX) side = next[side]++;
  for_each_chunk(texels, [&](size_t first, size_t last) {
    for (size_t i = first; i < last; ++i) {
      if (entry_of[i] == UINT32_MAX) continue;
      const LiveTexel& t = gbuffer.texels[i];
      float b1, b2;
      barycentrics_on_triangle(scene, t.triangle, t.position, b1, b2);
      const uint32_t e = entry_of[i];
      d.texel[e] = uint32_t(i);
      d.weight[e] = t.world_texel_size * t.world_texel_size;
      d.emitted[e] = emitted_radiance(scene, t.triangle, b1, b2);
      d.albedo[e] = t.albedo;
    }
  }, 16384);
  return d;
}

}  // namespace exitance
