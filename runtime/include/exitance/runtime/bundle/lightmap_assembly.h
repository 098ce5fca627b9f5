// Turns per-texel estimates into atlas page images: E/pi in R,G,B, coverage in A, direct/indirect
// layers, the estimated relative standard error in error.Y (LightmapEstimate::relative_standard_error
// with the estimate's error_floor), optional bounce<k> layers, and gutter texels dilated from their
// neighbours.
#pragma once
#include <vector>

#include "exitance/formats/lightmap_exr.h"
#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

struct AssemblyOptions {
  bool bounce_layers = false;  // write bounce<k>.R/G/B debug layers
  int dilation_texels = 4;     // how far colour is pushed into the gutter
};

std::vector<formats::LightmapImage> assemble_lightmap_pages(const TexelGBuffer& gbuffer, const LightmapEstimate& estimate,
                                                            const AssemblyOptions& options);

// Fills texels whose coverage is 0 with the mean of already-filled 8-neighbours, `passes` rings deep.
void dilate_into_gutter(int width, int height, const std::vector<float>& coverage, std::vector<float*> channels,
                        int passes);

}  // namespace exitance
