// One bounce layer B_k laid out on the atlas pages, for the per-bounce gather: the texels' means,
// dilated into the gutter (lightmap_assembly.h's dilate_into_gutter, as the bundle's pages are) so
// a bilinear lookup near a chart edge does not read unlit texels.
//
// Two resolution biases are kept out of the lookup, because both only ever darken:
// - texels inside or under geometry (most of their rays meet back faces, e.g. a wall behind a lamp
//   panel 1 cm in front of it) hold no light of a visible surface: they are left out like gutter
//   texels, and dilation refills them from valid neighbours;
// - a bilinear footprint can straddle a chart seam (the faces of a box packed side by side in UV):
//   a texel whose normal or plane differs from the hit's is not on the hit's surface and is left
//   out. Positions and normals are dilated with the colour, so gutter texels between two charts
//   carry a mixed normal and are left out too.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

// Which atlas cells a layer's cache holds and how the gutter fill reaches them: the valid live
// texels' cells (seeds), then each ring's cells with the filled neighbours each averages, in
// dilate_into_gutter's order. It depends only on the G-buffer, the texels' validity and the ring
// count, so one plan serves every layer of a bake (bounce_layer_cache.cpp).
struct BounceCachePlan;

class BounceLayerCache {
 public:
  // `texel_values`: B_k per live texel, in gbuffer.texels order; `valid`: per live texel, 0 for one
  // inside geometry (empty: all valid). `dilation`: rings filled around charts. `plan_from`: a cache
  // of the same bake whose plan is reused when built from the same G-buffer object, validity and
  // rings (so is this cache's own from its last build); the G-buffer must not change in between.
  void build(const TexelGBuffer& gbuffer, const std::vector<Vec3>& texel_values, const std::vector<uint8_t>& valid,
             int dilation, const BounceLayerCache* plan_from = nullptr);
  // B_k at lightmap UV `uv` of scene instance `instance`, hit at `position` on the side `normal`
  // (unit geometric normal): the bilinear mean of the footprint's lit texels on the same surface
  // (bounce_gather.h), renormalised over them; false when there is none, or the G-buffer has no
  // rectangle for the instance.
  bool lookup(const TexelGBuffer& gbuffer, uint32_t instance, Vec2 uv, Vec3 position, Vec3 normal, Vec3& out) const;
  // The pages' texels one after another (row 0 first), kBounceCacheTexelWords floats each, from
  // out[offset] (gpu_layout.h; the Vulkan backend's copy): colour, lit (1 where a valid texel or its
  // dilation holds a value, else the cell is all 0), the texel's world position and geometric normal.
  // `out` must have room.
  void interleave(std::vector<float>& out, size_t offset) const;

 private:
  // Only the cells the plan fills are stored (a city's atlas is ~85 % empty cells): the colour per
  // plan slot; positions and normals are the plan's, the same for every layer.
  std::shared_ptr<const BounceCachePlan> plan_;
  std::vector<Vec3> colour_;
};

}  // namespace exitance
