#include "exitance/runtime/bundle/texel_exitance.h"

#include <algorithm>
#include <cmath>

#include "exitance/common/sampling.h"
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

}  // namespace exitance
