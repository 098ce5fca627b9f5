#include "exitance/runtime/core/bounce_layer_cache.h"

#include <cmath>

#include "exitance/common/bounce_gather.h"
#include "exitance/common/gpu_layout.h"
#include "exitance/runtime/bundle/lightmap_assembly.h"

namespace exitance {
namespace {

enum Channel { kR, kG, kB, kLit, kPx, kPy, kPz, kNx, kNy, kNz, kChannels };
static_assert(kChannels == int(kBounceCacheTexelWords));

}  // namespace

void BounceLayerCache::build(const TexelGBuffer& gbuffer, const std::vector<Vec3>& texel_values,
                             const std::vector<uint8_t>& valid, int dilation) {
  pages_.resize(gbuffer.pages.size());
  for (size_t p = 0; p < pages_.size(); ++p) {
    Page& page = pages_[p];
    page.width = gbuffer.pages[p].width;
    page.height = gbuffer.pages[p].height;
    for (std::vector<float>& c : page.channel) c.assign(size_t(page.width) * size_t(page.height), 0.0f);
  }
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    const LiveTexel& t = gbuffer.texels[i];
    if (t.page >= pages_.size()) continue;  // a hand-made G-buffer without pages: nothing to look up
    if (!valid.empty() && !valid[i]) continue;
    Page& page = pages_[t.page];
    if (t.x >= uint32_t(page.width) || t.y >= uint32_t(page.height)) continue;
    const size_t at = size_t(t.y) * size_t(page.width) + size_t(t.x);
    const float values[kChannels] = {texel_values[i].x, texel_values[i].y, texel_values[i].z, 1.0f,
                                     t.position.x,      t.position.y,      t.position.z,      t.geometric_normal.x,
                                     t.geometric_normal.y, t.geometric_normal.z};
    for (int c = 0; c < kChannels; ++c) page.channel[c][at] = values[c];
  }
  // Every channel dilates: a filled gutter texel averages its lit neighbours (lit = 1).
  for (Page& page : pages_) {
    const std::vector<float> lit = page.channel[kLit];
    std::vector<float*> channels;
    for (std::vector<float>& c : page.channel) channels.push_back(c.data());
    dilate_into_gutter(page.width, page.height, lit, channels, dilation);
  }
}

bool BounceLayerCache::lookup(const TexelGBuffer& gbuffer, uint32_t instance, Vec2 uv, Vec3 position, Vec3 normal,
                              Vec3& out) const {
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
      if (!(page.channel[kLit][at] > 0)) continue;
      const Vec3 n{page.channel[kNx][at], page.channel[kNy][at], page.channel[kNz][at]};
      const Vec3 p{page.channel[kPx][at], page.channel[kPy][at], page.channel[kPz][at]};
      if (!texel_on_hit_surface(p, n, position, normal)) continue;
      const double w = bilinear_weight(f, dx, dy);
      weight += w;
      for (int c = 0; c < 3; ++c) sum[c] += w * page.channel[c][at];
    }
  if (!(weight > kLeastFootprintWeight)) return false;
  out = {float(sum[0] / weight), float(sum[1] / weight), float(sum[2] / weight)};
  return true;
}

}  // namespace exitance

namespace exitance {

void BounceLayerCache::interleave(std::vector<float>& out, size_t offset) const {
  for (const Page& page : pages_) {
    const size_t texels = size_t(page.width) * size_t(page.height);
    for (size_t t = 0; t < texels; ++t)
      for (int c = 0; c < kChannels; ++c) out[offset + t * kChannels + size_t(c)] = page.channel[c][t];
    offset += texels * kChannels;
  }
}

}  // namespace exitance
