#include "exitance/bake/command/gbuffer_without_skipped.h"

namespace exitance {

TexelGBuffer gbuffer_without_skipped(const TexelGBuffer& gbuffer, const std::vector<uint8_t>& skipped) {
  TexelGBuffer traced;
  traced.pages = gbuffer.pages;
  traced.skipped_texels = gbuffer.skipped_texels;
  traced.instance_rects = gbuffer.instance_rects;
  traced.texels.reserve(gbuffer.texels.size());
  for (size_t i = 0; i < gbuffer.texels.size(); ++i)
    if (!skipped[i]) traced.texels.push_back(gbuffer.texels[i]);
  return traced;
}

}  // namespace exitance
