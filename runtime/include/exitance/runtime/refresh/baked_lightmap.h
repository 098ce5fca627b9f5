// A bundle's baked lightmap as the estimate the runtime starts from (RefreshSession::open): each
// live texel's E/pi, direct part and error.Y read back from its page, with the variance of the mean
// that error.Y and the bake's error floor give (SE of the luminance = error.Y * (luminance + floor);
// per channel in proportion to its mean). Its sums are synthesized for the bake's smallest sample
// count per texel (published_estimate.h). Layers: bounce 0 = direct, bounce 1 = the rest.
#pragma once
#include <optional>
#include <string>

#include "exitance/formats/bundle_manifest.h"
#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

// Fewer samples per texel than this and the baked lightmap is not a starting state: its variances
// are too rough to weigh it against refreshed samples.
constexpr uint32_t kBakedStartMinimumSamples = 16;

// The baked lightmap of `bundle` (a folder) over `gbuffer`'s texels; nullopt when the bundle has no
// usable one: no pages, directional (sh1) layers, fewer than kBakedStartMinimumSamples samples per
// texel (stats.samples_per_texel.min; for a bundle exitance-relight wrote, relight.samples_per_texel.min,
// and its error floor from relight.error.floor), or pages without R, G, B, direct.R/G/B and error.Y. Throws
// std::runtime_error naming the file when a listed page cannot be read or does not match the
// G-buffer's page size.
//
// Light layers (docs/bundle.md "Light layers"): with `light_layers` > 0 (the count the session's
// scene lays out, `punctual_light_layers` of them punctual), the estimate has that many layers: the
// bundle's (their means times the same sample count) when its manifest lists them, else all 0
// (`has_light_layers` tells which). Throws std::runtime_error naming the manifest field when the
// bundle's layer counts differ from the session's, and (light_layer_pages.h) for a bad layer file.
struct BakedLightLayers {
  uint32_t count = 0;  // 0: not read (the session keeps no light layers)
  uint32_t punctual = 0;
};
std::optional<LightmapEstimate> read_baked_lightmap(const std::string& bundle, const formats::BundleManifest& manifest,
                                                    const TexelGBuffer& gbuffer, int recorded_bounces,
                                                    BakedLightLayers light_layers = {}, bool* has_light_layers = nullptr);

}  // namespace exitance
