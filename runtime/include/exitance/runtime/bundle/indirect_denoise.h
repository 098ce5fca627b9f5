// A texture-space filter of the lightmap's indirect light (bake --denoise, issue 34): each texel's
// indirect part (its total minus its direct light, TexelAccumulator::direct) becomes the
// weighted mean of the indirect parts of its atlas neighbours on the same surface
// (exitance/common/texture_space_filter.h), while its direct light stays as estimated. Indirect
// light varies slowly across a surface and carries most of a path-traced texel's noise, so the
// filter trades that noise for a bias where the indirect light changes within the window; it is off
// by default, and its bias is measured against converged path tracing (bench/results/denoise.md).
#pragma once
#include <cstddef>

#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

struct IndirectDenoiseSettings {
  int radius = 3;  // window of (2 radius + 1)^2 atlas texels
};

struct IndirectDenoiseReport {
  size_t texels = 0;             // texels filtered (with samples)
  double mean_neighbours = 0;    // texels with a weight > 0 per window, the texel itself included
  double seconds = 0;
};

// The estimate with each sampled texel's indirect part filtered: the mean becomes direct + the
// filtered indirect, the variance of the mean the neighbours' variances of their totals weighted as
// their means are (sum w^2 V / (sum w)^2, the texels' noise taken as independent), synthesized into
// the sums as set_total_sums does; recorded bounce layers 1 and up are filtered with the same
// weights, layer 0 (the direct light) is kept. Light layers and L1 sums are not split into direct and
// indirect: an estimate with either is refused (std::invalid_argument), as is one whose texels do
// not match the G-buffer or a radius outside 1 to 16.
LightmapEstimate denoise_indirect(const LightmapEstimate& estimate, const TexelGBuffer& gbuffer,
                                  const IndirectDenoiseSettings& settings, IndirectDenoiseReport* report = nullptr);

}  // namespace exitance
