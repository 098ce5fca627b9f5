// One bounce layer B_k laid out on the atlas pages, for the per-bounce gather: the texels' means,
// dilated into the gutter (lightmap_assembly.h's dilate_into_gutter, as the bundle's pages are) so
// a bilinear lookup near a chart edge does not read unlit texels, and a "lit" channel saying which
// texels hold a value.
#pragma once
#include <cstdint>
#include <vector>

#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

class BounceLayerCache {
 public:
  // `texel_values`: B_k per live texel, in gbuffer.texels order. `dilation`: rings filled around charts.
  void build(const TexelGBuffer& gbuffer, const std::vector<Vec3>& texel_values, int dilation);
  // B_k at lightmap UV `uv` of scene instance `instance`: the bilinear mean of the lit texels of its
  // footprint (bounce_gather.h), renormalised over them; false when none is lit or the G-buffer has
  // no rectangle for the instance.
  bool lookup(const TexelGBuffer& gbuffer, uint32_t instance, Vec2 uv, Vec3& out) const;

 private:
  struct Page {
    int width = 0, height = 0;
    std::vector<float> r, g, b, lit;  // planar, row 0 = top
  };
  std::vector<Page> pages_;
};

}  // namespace exitance
