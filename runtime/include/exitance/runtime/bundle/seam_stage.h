// The seam step of writing a bundle, shared by `bake` and `exitance-relight`: find the lightmap UV
// seams of every instance (seam_detection.h) and stitch the assembled pages (seam_stitching.h), or
// with stitching off only measure them, so a manifest shows what stitching would address.
#pragma once
#include <nlohmann/json.hpp>
#include <memory>
#include <vector>

#include "exitance/formats/lightmap_exr.h"
#include "exitance/runtime/bundle/seam_stitching.h"
#include "exitance/runtime/lightmap_atlas.h"
#include "exitance/runtime/scene.h"

namespace exitance {

// `dilation_passes`: the assembly's gutter dilation (AssemblyOptions::dilation_texels), repeated
// after the solve. Returns the manifest's `stats.seams` record (docs/bundle.md): mode, edges,
// samples, texels_adjusted, discontinuity_before/after, texel_relative_error, seconds.
nlohmann::json stitch_bundle_seams(std::vector<formats::LightmapImage>& pages, const Scene& scene,
                                   const AtlasLayout& atlas, int dilation_passes, bool stitch);

// The same page by page (pages assembled one at a time): page(p, image) for every page in ascending
// order, then report() is stitch_bundle_seams's record (its seconds: finding the seams and each
// page's stitching).
class BundleSeamStage {
 public:
  BundleSeamStage(const Scene& scene, const AtlasLayout& atlas, int dilation_passes, bool stitch);
  void page(size_t p, formats::LightmapImage& image);
  nlohmann::json report() const;

 private:
  std::unique_ptr<SeamStitcher> stitcher_;
  bool stitch_;
  double seconds_ = 0;
};

// The mode a bundle was written with: its manifest's stats.seams.mode ("stitch" or "off"); a bundle
// without the record (written before seams were stitched, or by hand) counts as the default, stitch.
bool bundle_stitches_seams(const std::string& stats_json);

}  // namespace exitance
