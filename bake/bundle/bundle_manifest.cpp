#include "exitance/bake/bundle/bundle_manifest.h"

#include "exitance/formats/scene_file.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>

#include "exitance/common/sampling.h"
#include "exitance/runtime/material_eval.h"

namespace exitance {

namespace {

using json = nlohmann::json;

json vec3_json(const std::array<float, 3>& v) { return json::array({v[0], v[1], v[2]}); }

// "settings": the options as the stages used them (the density, probe spacing and voxel resolution
// they chose when left automatic).
json settings_json(const BakeResults& results, const BakeOptions& options) {
  return {{"backend", results.backend.backend_name()},
          {"spp", options.lighting.spp},
          {"time_budget_seconds", options.lighting.time_budget_seconds},
          {"target_error", options.lighting.target_relative_error},
          {"bounces", options.lighting.max_bounces},
          {"seed", options.lighting.seed},
          {"texel_density", results.layout.texel_density},
          {"max_page", options.atlas.max_page},
          {"padding", options.atlas.padding},
          {"lightmap_uv", options.import.lightmap_uv_set},
          {"russian_roulette_start", options.lighting.russian_roulette_start},
          {"safety_bounce_cap", options.lighting.safety_bounce_cap},
          {"sky", options.sky},
          {"probes", results.probes ? json(results.probes->grid.spacing[0]) : json("none")},
          {"probe_spp", options.probe_spp},
          {"probe_dering_window", options.probe_sh_window},
          {"voxel_resolution", results.voxels ? json(results.voxels->svo.resolution()) : json("none")}};
}

json pages_json(const std::vector<formats::LightmapImage>& pages) {
  json list = json::array();
  for (size_t p = 0; p < pages.size(); ++p) {
    json channels = json::array();
    for (const auto& [name, data] : pages[p].channels) channels.push_back(name);
    list.push_back({{"file", "lightmap-" + std::to_string(p) + ".exr"},
                    {"width", pages[p].width},
                    {"height", pages[p].height},
                    {"channels", channels}});
  }
  return list;
}

json instances_json(const Scene& scene, const AtlasLayout& layout) {
  json list = json::array();
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const InstanceRect& r = layout.rects[i];
    list.push_back({{"node", scene.instances[i].node},
                    {"name", scene.instances[i].name},
                    {"mesh", scene.instances[i].mesh},
                    {"page", r.page},
                    {"scale_offset", {r.scale_offset[0], r.scale_offset[1], r.scale_offset[2], r.scale_offset[3]}},
                    {"rect", {r.x, r.y, r.width, r.height}}});
  }
  return list;
}

json probes_json(const ProbePlacement& probes) {
  const formats::ProbeGrid& grid = probes.grid;
  return {{"file", "probes.bin"},
          {"origin", vec3_json(grid.origin)},
          {"spacing", vec3_json(grid.spacing)},
          {"counts", {grid.counts[0], grid.counts[1], grid.counts[2]}},
          {"sh_order", 2},
          {"valid", probes.valid},
          {"moved", probes.moved},
          {"invalid", probes.invalid},
          {"skipped", probes.skipped}};
}

json svo_json(const formats::SparseVoxelOctree& svo) {
  const std::array<float, 3> hi{svo.origin[0] + svo.size, svo.origin[1] + svo.size, svo.origin[2] + svo.size};
  return {{"file", "svo.bin"},
          {"vdb", "radiance.vdb"},
          {"bounds", {vec3_json(svo.origin), vec3_json(hi)}},
          {"depth", svo.depth},
          {"nodes", svo.nodes.size()},
          {"units", "radiant_exitance"}};
}

// "stats": what each stage did and how long it took.
json stats_json(const BakeResults& results, const json& seconds, size_t warnings, const BakeOptions& options) {
  const TexelGBuffer& gbuffer = results.gbuffer;
  const LightmapEstimate& estimate = results.lightmap;
  // Mean relative standard error over live texels with signal; samples per texel.
  double relative_error_sum = 0;
  size_t relative_error_count = 0;
  uint64_t min_samples = gbuffer.texels.empty() ? 0 : UINT64_MAX, sample_sum = 0;
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    const float mean = luminance(estimate.mean_total(i));
    const float se = std::sqrt(luminance(estimate.variance_of_mean(i)));
    if (mean > 0) relative_error_sum += se / mean, ++relative_error_count;
    min_samples = std::min<uint64_t>(min_samples, estimate.texels[i].samples);
    sample_sum += estimate.texels[i].samples;
  }

  const double lighting_seconds = estimate.seconds;
  json stats;
  stats["seconds"] = seconds;
  stats["device"] = results.backend.device_description();
  stats["triangles"] = results.scene.triangle_count();
  stats["instances"] = results.scene.instances.size();
  stats["live_texels"] = gbuffer.texels.size();
  stats["rays"] = estimate.rays;
  stats["rays_per_second"] = lighting_seconds > 0 ? double(estimate.rays) / lighting_seconds : 0.0;
  stats["samples_per_texel"] = {{"min", min_samples},
                                {"mean", gbuffer.texels.empty() ? 0.0 : double(sample_sum) / double(gbuffer.texels.size())}};
  stats["estimated_relative_error"] = relative_error_count ? relative_error_sum / double(relative_error_count) : 0.0;
  stats["unoccluded_texels"] = results.unoccluded_texels;
  stats["enclosed_texels"] = results.geometry.enclosed_texels;
  stats["coplanar_texels"] = results.geometry.coplanar_texels;
  stats["enclosed_lights"] = results.geometry.enclosed_lights;
  stats["nonfinite_samples"] = estimate.nonfinite_samples;
  json skipped = {{"texels_outside_charts", gbuffer.skipped_texels}};
  if (results.probes) {
    const ProbePlacement& placement = *results.probes;
    const ProbeEstimate& probe_estimate = *results.probe_lighting;
    skipped["probes_far_from_geometry"] = placement.skipped;
    skipped["probes_inside_geometry"] = placement.invalid;
    stats["probes"] = {{"backend", results.backend.backend_name()},
                       {"grid", placement.grid.probes.size()},
                       {"valid", placement.valid},
                       {"moved", placement.moved},
                       {"invalid_inside_geometry", placement.invalid},
                       {"skipped_far_from_geometry", placement.skipped},
                       {"rays_per_probe", options.probe_spp},
                       {"rays", probe_estimate.rays},
                       {"rays_per_second",
                        probe_estimate.seconds > 0 ? double(probe_estimate.rays) / probe_estimate.seconds : 0.0},
                       {"nonfinite_samples", probe_estimate.nonfinite_samples}};
  } else {
    skipped["probes"] = "--probes none";
  }
  if (results.voxels) {
    const SvoBuildStatistics& svo_stats = results.voxels->statistics;
    stats["svo"] = {{"depth", results.voxels->svo.depth},
                    {"nodes", svo_stats.nodes},
                    {"leaves", svo_stats.leaves},
                    {"bytes_per_node", svo_stats.bytes_per_node},
                    {"bytes", svo_stats.total_bytes},
                    {"build_seconds", svo_stats.total_seconds}};
  } else {
    skipped["svo"] = "--voxel-resolution none";
  }
  stats["skipped"] = skipped;
  stats["warnings"] = warnings;
  return stats;
}

}  // namespace

json build_bundle_manifest(const BakeResults& results, const std::vector<formats::LightmapImage>& pages,
                           const std::string& input_sha256, const json& seconds, size_t warnings,
                           const BakeOptions& options) {
  json manifest;
  manifest["format_version"] = 1;
  manifest["generator"] = "exitance 0.1.0";
  manifest["input"] = {{"file", std::filesystem::path(options.input).filename().string()}, {"sha256", input_sha256}};
  manifest["units"] = {{"lightmap", "irradiance_over_pi"}, {"probes", "incident_radiance_sh_l2"}, {"length", "scene"}};
  manifest["settings"] = settings_json(results, options);
  manifest["pages"] = pages_json(pages);
  manifest["instances"] = instances_json(results.scene, results.layout);
  if (results.probes) manifest["probes"] = probes_json(*results.probes);
  if (results.voxels) manifest["svo"] = svo_json(results.voxels->svo);
  if (!results.scene_file.bytes.empty())
    manifest["scene"] = {{"file", "scene.bin"},
                         {"format_version", formats::kSceneFormatVersion},
                         {"bytes", results.scene_file.bytes.size()}};
  else
    manifest["scene"] = {{"skipped", results.scene_file.skipped}};
  manifest["stats"] = stats_json(results, seconds, warnings, options);
  return manifest;
}

}  // namespace exitance
