// Light layers in a bundle (docs/bundle.md "Light layers"): per atlas page one OpenEXR image whose
// channels "layer<k>.R/G/B" hold the mean E/pi of light layer k at each live texel (the gutter is
// 0: only live texels are ever read back). A layer that no texel of the page receives is left out of
// that page's file, so a building whose 48 rooms each have their own lamp stores each lamp's layer
// where it is not zero in practice only in ZIP's zero runs.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "exitance/formats/lightmap_exr.h"
#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

// "layer<k>.R" etc.; `channel` is 0, 1, 2 for R, G, B.
std::string light_layer_channel(uint32_t layer, int channel);

// The layer and channel a name gives, or nullopt when it is not "layer<k>.R/G/B" with k written in
// decimal without leading zeros.
struct LightLayerChannel {
  uint32_t layer = 0;
  int channel = 0;
};
std::optional<LightLayerChannel> parse_light_layer_channel(const std::string& name);

// One image per page of `gbuffer` with the bundle's layers: estimate layer j goes to bundle layer
// `bundle_layer[j]` (several estimate layers may add into one; see bundle_light_layer_map), means
// per texel (light_sums / samples; 0 for a texel without samples).
std::vector<formats::LightmapImage> assemble_light_layer_pages(const TexelGBuffer& gbuffer, const LightmapEstimate& estimate,
                                                               const std::vector<uint32_t>& bundle_layer);

// Per live texel and layer, the means read back: [layer][texel][rgb] (as LightmapEstimate's
// light_sums, divided by the samples). Throws std::runtime_error naming the file, channel and pixel
// for a page of another size, a channel that is not a layer below `layer_count`, a layer with fewer
// than all three channels, or a value that is not finite at a live texel.
std::vector<float> read_light_layer_pages(const std::vector<std::string>& files, const TexelGBuffer& gbuffer,
                                          uint32_t layer_count);

}  // namespace exitance
