#include "exitance/runtime/bundle/probe_results.h"

#include "exitance/runtime/spherical_harmonics.h"

namespace exitance {

void store_probe_radiance(formats::ProbeGrid& grid, const std::vector<size_t>& traced, const ProbeEstimate& estimate,
                          float dering_window) {
  for (size_t k = 0; k < traced.size(); ++k) {
    ShRgb sh = estimate.mean(k);
    if (dering_window > 0) sh_apply_hanning_window(sh, dering_window);
    formats::ProbeRecord& r = grid.probes[traced[k]];
    for (int i = 0; i < kShCoefficients; ++i)
      for (int c = 0; c < 3; ++c) r.sh[size_t(i) * 3 + size_t(c)] = is_finite(sh[size_t(i)]) ? sh[size_t(i)][c] : 0.0f;
  }
}

}  // namespace exitance
