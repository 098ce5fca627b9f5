#include "exitance/runtime/bundle/seam_stage.h"

#include <chrono>

#include "exitance/runtime/bundle/seam_detection.h"
#include "exitance/runtime/bundle/seam_stitching.h"

namespace exitance {

nlohmann::json stitch_bundle_seams(std::vector<formats::LightmapImage>& pages, const Scene& scene,
                                   const AtlasLayout& atlas, int dilation_passes, bool stitch) {
  const auto start = std::chrono::steady_clock::now();
  const std::vector<SeamEdge> seams = find_lightmap_seams(scene, atlas);
  SeamStitchSettings settings;
  settings.dilation_passes = dilation_passes;
  const SeamStitchReport report =
      stitch ? stitch_lightmap_seams(pages, seams, settings) : measure_lightmap_seams(pages, seams, settings);
  return {{"mode", stitch ? "stitch" : "off"},
          {"edges", report.edges},
          {"samples", report.samples},
          {"texels_adjusted", report.texels_adjusted},
          {"discontinuity_before", report.discontinuity_before},
          {"discontinuity_after", report.discontinuity_after},
          {"texel_relative_error", report.texel_relative_error},
          {"seconds", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()}};
}

bool bundle_stitches_seams(const std::string& stats_json) {
  if (stats_json.empty()) return true;
  const nlohmann::json stats = nlohmann::json::parse(stats_json, nullptr, false);
  if (!stats.is_object() || !stats.contains("seams") || !stats["seams"].is_object()) return true;
  const nlohmann::json& seams = stats["seams"];
  return !(seams.contains("mode") && seams["mode"].is_string() && seams["mode"].get<std::string>() == "off");
}

}  // namespace exitance
