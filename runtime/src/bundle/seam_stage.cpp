#include "exitance/runtime/bundle/seam_stage.h"

#include <chrono>

#include "exitance/runtime/bundle/seam_detection.h"
#include "exitance/runtime/bundle/seam_stitching.h"

namespace exitance {

BundleSeamStage::BundleSeamStage(const Scene& scene, const AtlasLayout& atlas, int dilation_passes, bool stitch)
    : stitch_(stitch) {
  const auto start = std::chrono::steady_clock::now();
  SeamStitchSettings settings;
  settings.dilation_passes = dilation_passes;
  stitcher_ = std::make_unique<SeamStitcher>(find_lightmap_seams(scene, atlas), settings, stitch);
  seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void BundleSeamStage::page(size_t p, formats::LightmapImage& image) {
  const auto start = std::chrono::steady_clock::now();
  stitcher_->page(p, image);
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

nlohmann::json BundleSeamStage::report() const {
  const SeamStitchReport report = stitcher_->report();
  return {{"mode", stitch_ ? "stitch" : "off"},
          {"edges", report.edges},
          {"samples", report.samples},
          {"texels_adjusted", report.texels_adjusted},
          {"discontinuity_before", report.discontinuity_before},
          {"discontinuity_after", report.discontinuity_after},
          {"texel_relative_error", report.texel_relative_error},
          {"seconds", seconds_}};
}

nlohmann::json stitch_bundle_seams(std::vector<formats::LightmapImage>& pages, const Scene& scene,
                                   const AtlasLayout& atlas, int dilation_passes, bool stitch) {
  BundleSeamStage stage(scene, atlas, dilation_passes, stitch);
  for (size_t p = 0; p < pages.size(); ++p) stage.page(p, pages[p]);
  return stage.report();
}

bool bundle_stitches_seams(const std::string& stats_json) {
  if (stats_json.empty()) return true;
  const nlohmann::json stats = nlohmann::json::parse(stats_json, nullptr, false);
  if (!stats.is_object() || !stats.contains("seams") || !stats["seams"].is_object()) return true;
  const nlohmann::json& seams = stats["seams"];
  return !(seams.contains("mode") && seams["mode"].is_string() && seams["mode"].get<std::string>() == "off");
}

}  // namespace exitance
