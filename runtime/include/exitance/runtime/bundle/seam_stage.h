// The seam step of writing a bundle, shared by `bake` and `exitance-relight`: find the lightmap UV
// seams of every instance (seam_detection.h) and stitch the assembled pages (seam_stitching.h), or
// with stitching off only measure them, so a manifest shows what stitching would address.
#pragma once
#include <nlohmann/json.hpp>
#include <vector>

#include "exitance/formats/lightmap_exr.h"
#include "exitance/runtime/lightmap_atlas.h"
#include "exitance/runtime/scene.h"

namespace exitance {

// `dilation_passes`: the assembly's gutter dilation (AssemblyOptions::dilation_texels), repeated
// after the solve. Returns the manifest's `stats.seams` record (docs/bundle.md): mode, edges,
// samples, texels_adjusted, discontinuity_before/after, texel_relative_error, seconds.
nlohmann::json stitch_bundle_seams(std::vector<formats::LightmapImage>& pages, const Scene& scene,
                                   const AtlasLayout& atlas, int dilation_passes, bool stitch);

// The mode a bundle was written with: its manifest's stats.seams.mode ("stitch" or "off"); a bundle
// without the record (written before seams were stitched, or by hand) counts as the default, stitch.
bool bundle_stitches_seams(const std::string& stats_json);

}  // namespace exitance
