// Whether two lightmap estimates hold the same bits in every texel's sums and bounce layers: the
// determinism checks (same seed, any thread count) of the guided integrators.
#pragma once
#include <cstring>

#include "exitance/runtime/core/estimates.h"

namespace exitance::testing {

inline bool identical_texel_sums(const LightmapEstimate& a, const LightmapEstimate& b) {
  if (a.texels.size() != b.texels.size() || a.bounces != b.bounces) return false;
  for (size_t i = 0; i < a.texels.size(); ++i)
    if (std::memcmp(&a.texels[i], &b.texels[i], sizeof(TexelAccumulator)) != 0) return false;
  return true;
}

}  // namespace exitance::testing
