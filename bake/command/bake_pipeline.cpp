#include "exitance/bake/command/bake_pipeline.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "exitance/bake/command/backend_choice.h"
#include "exitance/bake/bundle/input_hash.h"
#include "exitance/bake/raster/geometry_checks.h"
#include "exitance/bake/import/image_decode.h"
#include "exitance/bake/input_error.h"
#include "exitance/bake/probes/probe_placement.h"
#include "exitance/bake/bundle/radiance_vdb.h"
#include "exitance/bake/voxelize/svo_build.h"
#include "exitance/bake/raster/texel_raster.h"
#include "exitance/bake/raster/unocclude.h"
#include "exitance/formats/probes_file.h"
#include "exitance/runtime/bundle/bundle_directory.h"
#include "exitance/runtime/bundle/lightmap_assembly.h"
#include "exitance/runtime/bundle/probe_results.h"
#include "exitance/runtime/bundle/texel_exitance.h"
#include "exitance/formats/svo_file.h"
#include "exitance/runtime/cpu/bvh4_builder.h"
#include "exitance/runtime/embree_scene.h"
#include "exitance/runtime/material_eval.h"
#include "exitance/common/sampling.h"
#include "exitance/runtime/svo_exitance.h"

namespace exitance {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

class StageTimer {
 public:
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return seconds;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

json vec3_json(const std::array<float, 3>& v) { return json::array({v[0], v[1], v[2]}); }

}  // namespace

Sky parse_sky_option(const std::string& value) {
  Sky sky;
  if (value.empty()) return sky;
  std::stringstream stream(value);
  std::string part;
  std::vector<float> numbers;
  bool all_numbers = true;
  while (std::getline(stream, part, ',')) {
    try {
      size_t used = 0;
      const float v = std::stof(part, &used);
      if (used != part.size()) all_numbers = false;
      numbers.push_back(v);
    } catch (...) {
      all_numbers = false;
    }
  }
  if (all_numbers && numbers.size() == 3) {
    for (float v : numbers)
      if (!std::isfinite(v) || v < 0) throw InputError(value, "--sky", "colour components must be finite and >= 0");
    sky.constant = {numbers[0], numbers[1], numbers[2]};
    return sky;
  }
  if (all_numbers) throw InputError(value, "--sky", "expected R,G,B or an image file");
  sky.environment = read_linear_image_file(value, "--sky");
  return sky;
}

json run_bake(const BakeOptions& options, Diagnostics& diagnostics) {
  StageTimer timer;
  json seconds = json::object();
  auto report = [&](const std::string& stage, double fraction, uint64_t rays) {
    if (options.progress) options.progress(stage, fraction, rays);
  };

  report("import", 0, 0);
  Scene imported = import_gltf(options.input, options.import, diagnostics);
  imported.sky = parse_sky_option(options.sky);
  seconds["import"] = timer.lap();

  report("layout", 0, 0);
  const AtlasLayout layout = layout_lightmap_atlas(imported, options.atlas, options.input, diagnostics);
  seconds["layout"] = timer.lap();

  report("raster", 0, 0);
  TexelGBuffer gbuffer = rasterize_texel_gbuffer(imported, layout, options.input, diagnostics);
  seconds["raster"] = timer.lap();

  // One scene for every later stage: the Embree BVH (unocclude, checks, probe placement, the CPU
  // reference) and the lighting scene with its BVH4 (every backend).
  report("bvh", 0, 0);
  auto shared_scene = std::make_shared<const Scene>(std::move(imported));
  const Scene& scene = *shared_scene;
  auto embree_ptr = std::make_shared<const EmbreeScene>(scene);
  const EmbreeScene& embree = *embree_ptr;
  auto lighting_scene =
      std::make_shared<const LightingScene>(build_lighting_scene(shared_scene, build_bvh4(scene)));
  seconds["bvh"] = timer.lap();
  report("backend", 0, 0);
  const std::shared_ptr<const Integrator> backend =
      choose_lighting_backend(lighting_scene, embree_ptr, options.backend, diagnostics);
  seconds["backend"] = timer.lap();
  size_t moved = 0;
  GeometryCheckReport geometry;
  moved = unocclude_texels(embree, gbuffer).moved;
  seconds["unocclude"] = timer.lap();
  geometry = check_scene_geometry(scene, embree, gbuffer);
  for (std::string& line : describe_geometry_problems(geometry, scene, options.input)) diagnostics.warn(line);
  seconds["checks"] = timer.lap();

  // Voxelize before lighting so a bad --voxel-resolution fails before the long stage.
  formats::SparseVoxelOctree svo;
  SvoBuildStatistics svo_stats;
  if (options.svo_enabled) {
    report("voxelize", 0, 0);
    SvoBuildSettings svo_settings;
    try {
      svo_settings.depth = options.voxel_resolution ? svo_depth_from_resolution(options.voxel_resolution)
                                                    : default_svo_depth(scene, layout.texel_density);
    } catch (const std::invalid_argument& e) {
      throw InputError(options.input, "--voxel-resolution", e.what());
    }
    svo = build_sparse_voxel_octree(scene, svo_settings, &svo_stats);
    seconds["voxelize"] = timer.lap();
  }

  ProbePlacement placement;
  if (options.probes_enabled) {
    report("probe placement", 0, 0);
    ProbePlacementSettings probe_settings;
    probe_settings.spacing = options.probe_spacing;
    try {
      placement = place_probes(scene, embree, options.svo_enabled ? &svo : nullptr, probe_settings);
    } catch (const std::invalid_argument& e) {
      throw InputError(options.input, "--probes", e.what());
    }
    seconds["probe_placement"] = timer.lap();
  }

  IntegratorSettings lighting = options.lighting;
  lighting.progress = [&](double fraction, uint64_t rays) { report("lighting", fraction, rays); };
  const LightmapEstimate estimate = backend->bake(gbuffer, lighting);
  seconds["lighting"] = timer.lap();
  if (estimate.nonfinite_samples > 0)
    diagnostics.warn(options.input + ": " + std::to_string(estimate.nonfinite_samples) +
                     " path samples were NaN/Inf and were discarded (please report this scene)");

  if (options.svo_enabled) {
    report("exitance", 0, 0);
    fill_svo_exitance(svo, scene, gbuffer, estimate);
    seconds["exitance"] = timer.lap();
  }

  ProbeEstimate probe_estimate;
  if (options.probes_enabled) {
    std::vector<Vec3> positions;
    std::vector<size_t> traced;  // grid index of each traced probe
    for (size_t i = 0; i < placement.grid.probes.size(); ++i) {
      const formats::ProbeRecord& r = placement.grid.probes[i];
      if (!formats::probe_is_usable(r)) continue;
      positions.push_back({r.position[0], r.position[1], r.position[2]});
      traced.push_back(i);
    }
    IntegratorSettings probe_lighting = options.lighting;
    probe_lighting.spp = options.probe_spp;
    probe_lighting.time_budget_seconds = 0;
    probe_lighting.target_relative_error = 0;
    probe_lighting.progress = [&](double fraction, uint64_t rays) { report("probes", fraction, rays); };
    probe_estimate = backend->bake_probes(positions, probe_lighting);
    store_probe_radiance(placement.grid, traced, probe_estimate, options.probe_sh_window);
    seconds["probes"] = timer.lap();
    if (probe_estimate.nonfinite_samples > 0)
      diagnostics.warn(options.input + ": " + std::to_string(probe_estimate.nonfinite_samples) +
                       " probe samples were NaN/Inf and were discarded (please report this scene)");
  }

  report("write", 0, 0);
  AssemblyOptions assembly;
  assembly.bounce_layers = options.bounce_layers;
  assembly.dilation_texels = std::max(2, options.atlas.padding * 2);
  const std::vector<formats::LightmapImage> pages = assemble_lightmap_pages(gbuffer, estimate, assembly);

  // Statistics: mean relative standard error over live texels with signal.
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

  const fs::path input_path(options.input);
  const fs::path out = options.output.empty() ? fs::path(input_path).replace_extension(".bake") : fs::path(options.output);
  json manifest;
  manifest["format_version"] = 1;
  manifest["generator"] = "exitance 0.1.0";
  manifest["input"] = {{"file", input_path.filename().string()}, {"sha256", sha256_of_file(options.input)}};
  manifest["units"] = {{"lightmap", "irradiance_over_pi"}, {"probes", "incident_radiance_sh_l2"}, {"length", "scene"}};
  manifest["settings"] = {{"backend", backend->backend_name()},
                          {"spp", options.lighting.spp},
                          {"time_budget_seconds", options.lighting.time_budget_seconds},
                          {"target_error", options.lighting.target_relative_error},
                          {"bounces", options.lighting.max_bounces},
                          {"seed", options.lighting.seed},
                          {"texel_density", layout.texel_density},
                          {"max_page", options.atlas.max_page},
                          {"padding", options.atlas.padding},
                          {"lightmap_uv", options.import.lightmap_uv_set},
                          {"russian_roulette_start", options.lighting.russian_roulette_start},
                          {"safety_bounce_cap", options.lighting.safety_bounce_cap},
                          {"sky", options.sky},
                          {"probes", options.probes_enabled ? json(placement.grid.spacing[0]) : json("none")},
                          {"probe_spp", options.probe_spp},
                          {"probe_dering_window", options.probe_sh_window},
                          {"voxel_resolution", options.svo_enabled ? json(svo.resolution()) : json("none")}};
  json page_list = json::array();
  std::vector<std::string> layer_channels;
  for (size_t p = 0; p < pages.size(); ++p) {
    json channels = json::array();
    for (const auto& [name, data] : pages[p].channels) channels.push_back(name);
    page_list.push_back({{"file", "lightmap-" + std::to_string(p) + ".exr"},
                         {"width", pages[p].width},
                         {"height", pages[p].height},
                         {"channels", channels}});
  }
  manifest["pages"] = page_list;
  json instances = json::array();
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const InstanceRect& r = layout.rects[i];
    instances.push_back({{"node", scene.instances[i].node},
                         {"name", scene.instances[i].name},
                         {"mesh", scene.instances[i].mesh},
                         {"page", r.page},
                         {"scale_offset", {r.scale_offset[0], r.scale_offset[1], r.scale_offset[2], r.scale_offset[3]}},
                         {"rect", {r.x, r.y, r.width, r.height}}});
  }
  manifest["instances"] = instances;
  if (options.probes_enabled)
    manifest["probes"] = {{"file", "probes.bin"},
                          {"origin", vec3_json(placement.grid.origin)},
                          {"spacing", vec3_json(placement.grid.spacing)},
                          {"counts", {placement.grid.counts[0], placement.grid.counts[1], placement.grid.counts[2]}},
                          {"sh_order", 2},
                          {"valid", placement.valid},
                          {"moved", placement.moved},
                          {"invalid", placement.invalid},
                          {"skipped", placement.skipped}};
  if (options.svo_enabled) {
    const std::array<float, 3> hi{svo.origin[0] + svo.size, svo.origin[1] + svo.size, svo.origin[2] + svo.size};
    manifest["svo"] = {{"file", "svo.bin"},
                       {"vdb", "radiance.vdb"},
                       {"bounds", {vec3_json(svo.origin), vec3_json(hi)}},
                       {"depth", svo.depth},
                       {"nodes", svo.nodes.size()},
                       {"units", "radiant_exitance"}};
  }
  const double lighting_seconds = estimate.seconds;
  json stats;
  stats["seconds"] = seconds;
  stats["device"] = backend->device_description();
  stats["triangles"] = scene.triangle_count();
  stats["instances"] = scene.instances.size();
  stats["live_texels"] = gbuffer.texels.size();
  stats["rays"] = estimate.rays;
  stats["rays_per_second"] = lighting_seconds > 0 ? double(estimate.rays) / lighting_seconds : 0.0;
  stats["samples_per_texel"] = {{"min", min_samples},
                                {"mean", gbuffer.texels.empty() ? 0.0 : double(sample_sum) / double(gbuffer.texels.size())}};
  stats["estimated_relative_error"] = relative_error_count ? relative_error_sum / double(relative_error_count) : 0.0;
  stats["unoccluded_texels"] = moved;
  stats["enclosed_texels"] = geometry.enclosed_texels;
  stats["coplanar_texels"] = geometry.coplanar_texels;
  stats["enclosed_lights"] = geometry.enclosed_lights;
  stats["nonfinite_samples"] = estimate.nonfinite_samples;
  json skipped = {{"texels_outside_charts", gbuffer.skipped_texels}};
  if (options.probes_enabled) {
    skipped["probes_far_from_geometry"] = placement.skipped;
    skipped["probes_inside_geometry"] = placement.invalid;
    stats["probes"] = {{"backend", backend->backend_name()},
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
  if (options.svo_enabled) {
    stats["svo"] = {{"depth", svo.depth},
                    {"nodes", svo_stats.nodes},
                    {"leaves", svo_stats.leaves},
                    {"bytes_per_node", svo_stats.bytes_per_node},
                    {"bytes", svo_stats.total_bytes},
                    {"build_seconds", svo_stats.total_seconds}};
  } else {
    skipped["svo"] = "--voxel-resolution none";
  }
  stats["skipped"] = skipped;
  stats["warnings"] = diagnostics.warnings.size();
  manifest["stats"] = stats;

  write_bundle_atomically(out, [&](const fs::path& dir) {
    for (size_t p = 0; p < pages.size(); ++p)
      formats::write_lightmap_exr((dir / ("lightmap-" + std::to_string(p) + ".exr")).string(), pages[p]);
    if (options.probes_enabled) formats::write_probes_file((dir / "probes.bin").string(), placement.grid);
    if (options.svo_enabled) {
      formats::write_svo_file((dir / "svo.bin").string(), svo);
      write_radiance_vdb((dir / "radiance.vdb").string(), svo);
    }
    std::ofstream file(dir / "manifest.json");
    file << manifest.dump(2) << "\n";
    if (!file) throw std::runtime_error("cannot write " + (dir / "manifest.json").string());
  });
  seconds["write"] = timer.lap();
  json result = stats;
  result["seconds"] = seconds;
  result["output"] = fs::absolute(out).string();
  result["pages"] = pages.size();
  return result;
}

}  // namespace exitance
