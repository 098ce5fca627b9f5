// Probe estimates into the probe grid that probes.bin stores.
#pragma once
#include <cstddef>
#include <vector>

#include "exitance/formats/probe_grid.h"
#include "exitance/runtime/core/estimates.h"

namespace exitance {

// Probe k of the estimate is grid probe traced[k]: its mean SH of incident radiance, optionally
// deringed with a Hanning window of `dering_window` bands (0 = off); non-finite sets store zeros.
void store_probe_radiance(formats::ProbeGrid& grid, const std::vector<size_t>& traced, const ProbeEstimate& estimate,
                          float dering_window);

}  // namespace exitance
