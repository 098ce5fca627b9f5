// Trilinear interpolation of the probe grid's SH coefficients, with unusable probes
// (formats::probe_is_usable false: Invalid, Skipped) weighted out and the remaining weights
// renormalised, so probes inside walls do not leak darkness.
#pragma once
#include <cstddef>  // probe_grid.h uses size_t without including it

#include "exitance/formats/probe_grid.h"
#include "exitance/loader/lookup_results.h"

namespace exitance::loader {

// The grid must be validated (formats::validate_probe_grid) and the point finite. Points outside
// the grid use its nearest cell (clamped). Interpolation uses the probes' grid positions, not
// their moved positions. When every usable probe of the cell has zero trilinear weight (the point
// lies on an unusable probe), the usable probes of the cell are averaged with equal weights.
ProbeShResult interpolate_probe_sh(const formats::ProbeGrid& grid, Point3 point);

// E(n)/pi from interpolated coefficients: the clamped-cosine convolution (band factors pi, 2pi/3,
// pi/4) divided by pi. `normal` must be finite and non-zero; it is normalised here.
ProbeIrradianceResult probe_irradiance_over_pi(const formats::ProbeGrid& grid, Point3 point, Point3 normal);

}  // namespace exitance::loader
