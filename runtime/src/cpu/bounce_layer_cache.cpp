#include "bounce_layer_cache.h"

#include "exitance/common/bounce_gather.h"
#include "exitance/runtime/bundle/lightmap_assembly.h"

namespace exitance {

void BounceLayerCache::build(const TexelGBuffer& gbuffer, const std::vector<Vec3>& texel_values, int dilation) {
  pages_.resize(gbuffer.pages.size());
  for (size_t p = 0; p < pages_.size(); ++p) {
    Page& page = pages_[p];
    page.width = gbuffer.pages[p].width;
    page.height = gbuffer.pages[p].height;
    const size_t n = size_t(page.width) * size_t(page.height);
    for (std::vector<float>* channel : {&page.r, &page.g, &page.b, &page.lit}) channel->assign(n, 0.0f);
  }
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    const LiveTexel& t = gbuffer.texels[i];
    if (t.page >= pages_.size()) continue;  // a hand-made G-buffer without pages: nothing to look up
    Page& page = pages_[t.page];
    if (t.x >= uint32_t(page.width) || t.y >= uint32_t(page.height)) continue;
    const size_t at = size_t(t.y) * size_t(page.width) + size_t(t.x);
    page.r[at] = texel_values[i].x;
    page.g[at] = texel_values[i].y;
    page.b[at] = texel_values[i].z;
    page.lit[at] = 1.0f;
  }
  // The "lit" channel dilates with the colour: a filled gutter texel averages lit neighbours (1).
  for (size_t p = 0; p < pages_.size(); ++p) {
    Page& page = pages_[p];
    const std::vector<float> live = page.lit;
    dilate_into_gutter(page.width, page.height, live, {page.r.data(), page.g.data(), page.b.data(), page.lit.data()},
                       dilation);
  }
}

bool BounceLayerCache::lookup(const TexelGBuffer& gbuffer, uint32_t instance, Vec2 uv, Vec3& out) const {
  if (instance >= gbuffer.instance_rects.size()) return false;
  const InstanceRect& rect = gbuffer.instance_rects[instance];
  if (rect.page < 0 || size_t(rect.page) >= pages_.size()) return false;
  const Page& page = pages_[size_t(rect.page)];
  const Vec4 scale_offset{rect.scale_offset[0], rect.scale_offset[1], rect.scale_offset[2], rect.scale_offset[3]};
  const BilinearFootprint f = bilinear_footprint(lightmap_page_uv(uv, scale_offset), page.width, page.height);
  double weight = 0, sum[3] = {0, 0, 0};
  for (int dy = 0; dy <= 1; ++dy)
    for (int dx = 0; dx <= 1; ++dx) {
      const int x = f.x0 + dx, y = f.y0 + dy;
      if (x < 0 || y < 0 || x >= page.width || y >= page.height) continue;
      const size_t at = size_t(y) * size_t(page.width) + size_t(x);
      if (!(page.lit[at] > 0)) continue;
      const double w = bilinear_weight(f, dx, dy);
      weight += w;
      sum[0] += w * page.r[at];
      sum[1] += w * page.g[at];
      sum[2] += w * page.b[at];
    }
  // A footprint whose lit texels carry almost no weight would amplify one texel's noise: treat as none.
  if (!(weight > 1e-3)) return false;
  out = {float(sum[0] / weight), float(sum[1] / weight), float(sum[2] / weight)};
  return true;
}

}  // namespace exitance
