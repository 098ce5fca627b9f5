#include "exitance/bake/bundle/bundle_manifest.h"

#include "exitance/formats/scene_file.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>

#include "exitance/common/path_sampler.h"
#include "exitance/common/sampling.h"
#include "exitance/runtime/bundle/bounce_statistics_report.h"
#include "exitance/runtime/bundle/emitter_guiding_report.h"
#include "exitance/runtime/bundle/guiding_auto_report.h"
#include "exitance/runtime/bundle/light_paths_report.h"
#include "exitance/runtime/material_eval.h"

namespace exitance {

namespace {

using json = nlohmann::json;

// "settings": the options as the stages used them (the density, probe spacing and voxel resolution
// they chose when left automatic).
formats::BakeSettings settings_of(const BakeResults& results, const BakeOptions& options) {
  formats::BakeSettings s;
  s.backend = results.backend.backend_name();
  s.integrator = options.lighting.integrator == IntegratorMode::Bounces ? "bounces" : "path";
  s.spp = options.lighting.spp;
  s.time_budget_seconds = options.lighting.time_budget_seconds;
  s.target_error = options.lighting.target_relative_error;
  s.adaptive = results.lightmap.adaptive;
  s.sampler = options.lighting.sampler == kSamplerIndependent ? "independent" : "sobol";
  s.first_bounce = options.lighting.trace_first_bounce ? "traced" : "cached";
  s.directional = results.lightmap.has_sh1() ? "sh1" : "off";
  s.bounces = options.lighting.max_bounces;
  s.seed = options.lighting.seed;
  s.texel_density = results.layout.texel_density;
  s.max_page = uint32_t(options.atlas.max_page);
  s.padding = uint32_t(options.atlas.padding);
  s.lightmap_uv = uint32_t(options.import.lightmap_uv_set);
  s.lightmap_uv_generate = options.import.generate_lightmap_uvs;
  if (results.generated_uvs)
    for (const MeshUvReport& r : *results.generated_uvs) s.generated_uv_meshes.push_back(uint32_t(r.mesh));
  s.russian_roulette_start = options.lighting.russian_roulette_start;
  s.safety_bounce_cap = options.lighting.safety_bounce_cap;
  s.sky = options.sky;
  if (results.probes) s.probe_spacing = results.probes->grid.spacing[0];
  s.probe_spp = options.probe_spp;
  s.probe_dering_window = options.probe_sh_window;
  if (results.voxels) s.voxel_resolution = results.voxels->svo.resolution();
  return s;
}

std::vector<formats::PageInfo> pages_of(const std::vector<formats::LightmapImage>& pages) {
  std::vector<formats::PageInfo> list;
  for (size_t p = 0; p < pages.size(); ++p) {
    formats::PageInfo& page = list.emplace_back();
    page.file = "lightmap-" + std::to_string(p) + ".exr";
    page.width = uint32_t(pages[p].width);
    page.height = uint32_t(pages[p].height);
    for (const auto& [name, data] : pages[p].channels) page.channels.push_back(name);
  }
  return list;
}

std::vector<formats::InstanceInfo> instances_of(const Scene& scene, const AtlasLayout& layout) {
  std::vector<formats::InstanceInfo> list;
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const InstanceRect& r = layout.rects[i];
    formats::InstanceInfo& instance = list.emplace_back();
    instance.node = uint32_t(scene.instances[i].node);
    instance.name = scene.instances[i].name;
    instance.mesh = uint32_t(scene.instances[i].mesh);
    instance.page = uint32_t(r.page);
    instance.scale_offset = {r.scale_offset[0], r.scale_offset[1], r.scale_offset[2], r.scale_offset[3]};
    instance.rect = std::array<uint32_t, 4>{uint32_t(r.x), uint32_t(r.y), uint32_t(r.width), uint32_t(r.height)};
  }
  return list;
}

formats::ProbeGridInfo probes_of(const ProbePlacement& probes) {
  const formats::ProbeGrid& grid = probes.grid;
  formats::ProbeGridInfo info;
  info.file = "probes.bin";
  info.origin = grid.origin;
  info.spacing = grid.spacing;
  info.counts = grid.counts;
  info.sh_order = 2;
  info.placement = formats::ProbePlacementCounts{probes.valid, probes.moved, probes.invalid, probes.skipped};
  return info;
}

formats::SvoInfo svo_of(const formats::SparseVoxelOctree& svo) {
  formats::SvoInfo info;
  info.file = "svo.bin";
  info.vdb = "radiance.vdb";
  info.bounds_min = svo.origin;
  info.bounds_max = {svo.origin[0] + svo.size, svo.origin[1] + svo.size, svo.origin[2] + svo.size};
  info.depth = svo.depth;
  info.nodes = svo.nodes.size();
  return info;
}

// stats.error: the distribution over traced texels of the EXR's error layer (relative standard error with
// the floor), and the floor itself.
json error_distribution_json(const LightmapEstimate& estimate) {
  const double floor = estimate.error_floor();
  std::vector<float> errors;  // over traced texels (skipped sealed texels have no samples)
  for (size_t i = 0; i < estimate.texels.size(); ++i)
    if (estimate.texels[i].samples > 0) errors.push_back(estimate.relative_standard_error(i, floor));
  std::sort(errors.begin(), errors.end());
  auto quantile = [&](double q) {
    return errors.empty() ? 0.0 : double(errors[std::min(errors.size() - 1, size_t(q * double(errors.size())))]);
  };
  double sum = 0;
  for (float e : errors) sum += e;
  return {{"floor", floor},
          {"mean", errors.empty() ? 0.0 : sum / double(errors.size())},
          {"p50", quantile(0.5)},
          {"p90", quantile(0.9)},
          {"p99", quantile(0.99)},
          {"max", errors.empty() ? 0.0 : double(errors.back())}};
}

// "stats": what each stage did and how long it took.
json stats_json(const BakeResults& results, const json& seconds, size_t warnings, const BakeOptions& options) {
  const TexelGBuffer& gbuffer = results.gbuffer;
  const LightmapEstimate& estimate = results.lightmap;
  // Samples per traced texel: skipped sealed texels have none by design.
  auto skipped_sealed = [&](size_t i) { return results.sealed_skipped && results.sealed && results.sealed->sealed[i]; };
  uint64_t min_samples = UINT64_MAX, max_samples = 0, sample_sum = 0, traced = 0;
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    if (skipped_sealed(i)) continue;
    min_samples = std::min<uint64_t>(min_samples, estimate.texels[i].samples);
    max_samples = std::max<uint64_t>(max_samples, estimate.texels[i].samples);
    sample_sum += estimate.texels[i].samples;
    ++traced;
  }
  if (traced == 0) min_samples = 0;

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
                                {"max", max_samples},
                                {"mean", traced == 0 ? 0.0 : double(sample_sum) / double(traced)}};
  if (estimate.adaptive) stats["samples_per_texel"]["pilot"] = estimate.adaptive_pilot;
  stats["estimated_relative_error"] = estimate.mean_relative_standard_error();
  stats["error"] = error_distribution_json(estimate);
  stats["unoccluded_texels"] = results.unoccluded_texels;
  stats["enclosed_texels"] = results.geometry.enclosed_texels;
  stats["coplanar_texels"] = results.geometry.coplanar_texels;
  stats["enclosed_lights"] = results.geometry.enclosed_lights;
  stats["nonfinite_samples"] = estimate.nonfinite_samples;
  // What the automatic choices decided (--integrator, --guiding, --emitter-guiding auto), so a
  // report says which estimator lit this scene; "auto" guiding's per-region choice is "guiding".
  const char* guiding_names[] = {"off", "grid", "svo", "auto"};
  stats["lighting"] = {{"integrator", options.lighting.integrator == IntegratorMode::Bounces ? "bounces" : "path"},
                       {"guiding", guiding_names[int(options.lighting.guiding)]},
                       {"emitter_guiding", options.lighting.emitter_guiding},
                       {"light_paths", options.lighting.light_subpaths}};
  if (options.lighting.light_subpaths || estimate.light_subpaths > 0) {
    stats["light_paths"] = light_paths_json(estimate);
    stats["light_paths"]["per_sample"] = options.lighting.light_subpaths_per_sample;
  }
  if (results.denoise)
    stats["denoise"] = {{"radius", options.denoise_radius},
                        {"texels", results.denoise->texels},
                        {"mean_neighbours", results.denoise->mean_neighbours},
                        {"seconds", results.denoise->seconds}};
  if (estimate.guiding_auto) stats["guiding"] = guiding_auto_json(estimate, results.backend.backend_name());
  if (estimate.emitter_guiding.records > 0) stats["emitter_guiding"] = emitter_guiding_json(estimate.emitter_guiding);
  if (options.lighting.integrator == IntegratorMode::Bounces && !estimate.bounce_statistics.samples.empty())
    stats["bounces"] = bounce_statistics_json(estimate.bounce_statistics);
  if (results.stage_cache) stats["cache"]["stages"] = *results.stage_cache;
  if (results.distribution)
    for (const auto& [key, value] : results.distribution->items()) stats[key] = value;
  json skipped = {{"texels_outside_charts", gbuffer.skipped_texels}};
  if (results.sealed) {
    // Sealed texels (no light reaches them): found either way, skipped unless --no-skip. The time
    // saved is an estimate: the lighting stage's seconds per traced texel times the texels skipped
    // (bench/results/dead-work.md measures it with and without the skip).
    const SealedTexels& sealed = *results.sealed;
    stats["sealed_texels"] = {{"found", sealed.texels}, {"instances", sealed.instances},
                              {"candidates", sealed.candidates}, {"skipped", results.sealed_skipped}};
    const size_t sealed_skipped = results.sealed_skipped ? sealed.texels : 0;
    skipped["sealed_texels"] = sealed_skipped;
    skipped["sealed_instances"] = results.sealed_skipped ? sealed.instances : 0;
    skipped["sealed_lighting_seconds_saved_estimate"] =
        traced > 0 ? lighting_seconds / double(traced) * double(sealed_skipped) : 0.0;
  }
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
                       // What ran: a --time budget can end probes before --probe-spp.
                       {"rays_per_probe", probe_estimate.samples.empty()
                                              ? uint64_t(options.probe_spp)
                                              : uint64_t(*std::min_element(probe_estimate.samples.begin(),
                                                                           probe_estimate.samples.end()))},
                       {"rays", probe_estimate.rays},
                       {"rays_per_second",
                        probe_estimate.seconds > 0 ? double(probe_estimate.rays) / probe_estimate.seconds : 0.0},
                       {"nonfinite_samples", probe_estimate.nonfinite_samples},
                       // Light subpaths traced for the probes' connections (0: none connected).
                       {"light_subpaths", probe_estimate.light_subpaths}};
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
  if (results.generated_uvs && !results.generated_uvs->empty()) {
    json meshes = json::array();
    for (const MeshUvReport& r : *results.generated_uvs) {
      const UvGenerationStats& u = r.stats;
      meshes.push_back({{"mesh", r.mesh},
                        {"name", r.name},
                        {"reason", r.missing_set.empty() ? std::string("--uv generate") : "no " + r.missing_set},
                        {"triangles", u.triangles},
                        {"charts", u.charts},
                        {"lscm_charts", u.lscm_charts},
                        {"planar_charts", u.planar_charts},
                        {"degenerate_triangles", u.degenerate_triangles},
                        {"stretched_charts", u.stretched_charts},
                        {"utilization", u.utilization},
                        {"area_distortion", {{"max", u.max_area_distortion}, {"mean", u.mean_area_distortion}}},
                        {"angle_distortion", {{"max", u.max_angle_distortion}, {"mean", u.mean_angle_distortion}}},
                        {"packed_texels", {u.packed_width, u.packed_height}},
                        {"texels_per_unit", u.texels_per_unit},
                        {"gutter_holds", u.gutter_holds},
                        {"seconds", r.seconds}});
    }
    stats["generated_lightmap_uvs"] = meshes;
  }
  stats["skipped"] = skipped;
  stats["warnings"] = warnings;
  return stats;
}

}  // namespace

formats::BundleManifest build_bundle_manifest(const BakeResults& results,
                                              const std::vector<formats::LightmapImage>& pages,
                                              const std::string& input_sha256, const json& seconds, size_t warnings,
                                              const BakeOptions& options) {
  formats::BundleManifest manifest;
  manifest.generator = "exitance 0.1.0";
  manifest.input = formats::InputInfo{std::filesystem::path(options.input).filename().string(), input_sha256};
  manifest.settings = settings_of(results, options);
  manifest.pages = pages_of(pages);
  manifest.instances = instances_of(results.scene, results.layout);
  if (results.probes) manifest.probes = probes_of(*results.probes);
  if (results.voxels) manifest.svo = svo_of(results.voxels->svo);
  formats::SceneFileInfo scene;
  const PersistedSceneFile& scene_file = results.scene_file.get();
  if (!scene_file.bytes.empty()) {
    scene.file = "scene.bin";
    scene.format_version = formats::kSceneFormatVersion;
    scene.bytes = scene_file.bytes.size();
  } else {
    scene.skipped = scene_file.skipped;
  }
  manifest.scene = scene;
  manifest.stats_json = stats_json(results, seconds, warnings, options).dump();
  return manifest;
}

}  // namespace exitance
