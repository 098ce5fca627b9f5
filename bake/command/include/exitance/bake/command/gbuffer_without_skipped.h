// The G-buffer the lighting stage traces when sealed texels are skipped: the same pages and
// instance rectangles, only the texels to trace (every backend lights whatever texel list it gets).
#pragma once
#include <cstdint>
#include <vector>

#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

// The texels whose entry in `skipped` is 0, in order; pages and instance_rects unchanged.
TexelGBuffer gbuffer_without_skipped(const TexelGBuffer& gbuffer, const std::vector<uint8_t>& skipped);

}  // namespace exitance
