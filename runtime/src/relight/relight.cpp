#include "exitance/runtime/relight/relight.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>

#include "exitance/formats/bundle_manifest.h"
#include "exitance/formats/format_error.h"
#include "exitance/formats/probes_file.h"
#include "exitance/formats/scene_file.h"
#include "exitance/formats/svo_file.h"
#include "exitance/runtime/bundle/bundle_directory.h"
#include "exitance/runtime/bundle/lightmap_assembly.h"
#include "exitance/runtime/bundle/probe_results.h"
#include "exitance/runtime/bundle/texel_exitance.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/scene_file_conversion.h"
#include "exitance/runtime/vulkan/validation_messages.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"

namespace exitance {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

formats::BundleManifest read_manifest(const fs::path& bundle) {
  const fs::path path = bundle / "manifest.json";
  std::ifstream in(path, std::ios::binary);
  if (!in) throw RelightInputError(path.string() + ": cannot read the manifest (is " + bundle.string() + " a bundle?)");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    return formats::parse_bundle_manifest(text, path.string());
  } catch (const formats::FormatError& e) {
    throw RelightInputError(e.what());
  }
}

}  // namespace

json relight_bundle(const RelightOptions& options) {
  using Clock = std::chrono::steady_clock;
  auto last = Clock::now();
  json seconds = json::object();
  auto lap = [&](const char* stage) {
    const auto now = Clock::now();
    seconds[stage] = std::chrono::duration<double>(now - last).count();
    last = now;
  };
  auto report = [&](const std::string& stage, double fraction, uint64_t rays) {
    if (options.progress) options.progress(stage, fraction, rays);
  };

  const fs::path bundle(options.bundle);
  const fs::path out = options.output.empty() ? bundle : fs::path(options.output);
  report("load", 0, 0);
  formats::BundleManifest manifest = read_manifest(bundle);
  if (!manifest.scene)
    throw RelightInputError((bundle / "manifest.json").string() + ": scene: missing (baked before scene.bin existed); re-bake instead");
  if (manifest.scene->file.empty())
    throw RelightInputError((bundle / "manifest.json").string() + ": scene: bake wrote no scene.bin (" +
                            manifest.scene->skipped + "); re-bake instead");
  // Settings absent from an older manifest take bake's defaults (formats::BakeSettings).
  const formats::BakeSettings baked = manifest.settings.value_or(formats::BakeSettings{});
  PersistedScene persisted;
  formats::SparseVoxelOctree svo;
  const bool has_svo = manifest.svo.has_value();
  formats::SceneFile scene_file;  // kept to write it back: encoding a file that was read gives its bytes again
  try {
    scene_file = formats::read_scene_file((bundle / manifest.scene->file).string());
    persisted = restore_scene(scene_file);
    if (has_svo) svo = formats::read_svo_file((bundle / manifest.svo->file).string());
  } catch (const formats::FormatError& e) {
    throw RelightInputError(e.what());
  }
  lap("load");

  IntegratorSettings lighting;
  lighting.spp = options.spp ? *options.spp : (options.time_budget_seconds > 0 ? 0u : baked.spp);
  lighting.time_budget_seconds = options.time_budget_seconds;
  lighting.seed = options.seed ? *options.seed : baked.seed;
  lighting.max_bounces = baked.bounces;
  lighting.russian_roulette_start = baked.russian_roulette_start;
  lighting.safety_bounce_cap = baked.safety_bounce_cap;
  lighting.target_relative_error = baked.target_error;
  const uint32_t probe_spp = baked.probe_spp;
  const float probe_dering = baked.probe_dering_window;
  if (lighting.spp == 0 && !(lighting.time_budget_seconds > 0) && !(lighting.target_relative_error > 0))
    throw RelightInputError("--spp 0 needs --time");

  report("upload", 0, 0);
  auto scene = std::make_shared<const Scene>(std::move(persisted.scene));
  std::shared_ptr<const LightingScene> lighting_scene;
  try {
    lighting_scene = std::make_shared<const LightingScene>(build_lighting_scene(scene, to_bvh4(persisted.bvh)));
  } catch (const std::invalid_argument& e) {
    throw RelightInputError((bundle / "scene.bin").string() + ": " + e.what());
  }
  VulkanDeviceOptions device;
  device.device_index = options.device_index;
  device.validation = options.validation;
  device.collect_stage_statistics = options.stage_statistics;
  auto validation = std::make_shared<ValidationMessages>();
  if (options.validation) device.on_validation_message = ValidationMessages::collector(validation);
  const std::unique_ptr<VulkanIntegrator> integrator = VulkanIntegrator::create(lighting_scene, device);
  lap("upload");

  lighting.progress = [&](double fraction, uint64_t rays) { report("lighting", fraction, rays); };
  const LightmapEstimate estimate = integrator->bake(persisted.gbuffer, lighting);
  lap("lighting");
  json stages = json::array();
  if (options.stage_statistics)
    for (const VulkanStageStatistics& s : integrator->stage_statistics())
      stages.push_back({{"stage", s.stage}, {"gpu_seconds", s.seconds}, {"items", s.items}, {"rays", s.rays},
                        {"lane_efficiency", s.lane_efficiency}});

  ProbeEstimate probe_estimate;
  const bool has_probes = persisted.has_probe_grid() && manifest.probes.has_value();
  if (has_probes) {
    std::vector<Vec3> positions;
    std::vector<size_t> traced;
    for (size_t i = 0; i < persisted.probes.probes.size(); ++i) {
      const formats::ProbeRecord& r = persisted.probes.probes[i];
      if (!formats::probe_is_usable(r)) continue;
      positions.push_back({r.position[0], r.position[1], r.position[2]});
      traced.push_back(i);
    }
    IntegratorSettings probe_lighting = lighting;
    probe_lighting.spp = probe_spp;
    probe_lighting.time_budget_seconds = 0;
    probe_lighting.target_relative_error = 0;
    probe_lighting.progress = [&](double fraction, uint64_t rays) { report("probes", fraction, rays); };
    probe_estimate = integrator->bake_probes(positions, probe_lighting);
    store_probe_radiance(persisted.probes, traced, probe_estimate, probe_dering);
    lap("probes");
  }
  validation->throw_if_any();

  if (has_svo) {
    report("exitance", 0, 0);
    fill_svo_exitance(svo, *scene, persisted.gbuffer, estimate);
    lap("exitance");
  }

  report("write", 0, 0);
  AssemblyOptions assembly;
  assembly.bounce_layers = manifest.has_bounce_layers();
  assembly.dilation_texels = std::max(2, int(baked.padding) * 2);
  const std::vector<formats::LightmapImage> pages = assemble_lightmap_pages(persisted.gbuffer, estimate, assembly);

  double relative_error_sum = 0;
  size_t relative_error_count = 0;
  for (size_t i = 0; i < persisted.gbuffer.texels.size(); ++i) {
    const float mean = luminance(estimate.mean_total(i));
    const float se = std::sqrt(luminance(estimate.variance_of_mean(i)));
    if (mean > 0) relative_error_sum += se / mean, ++relative_error_count;
  }
  json run;
  run["tool"] = "exitance-relight";
  run["source_bundle"] = fs::absolute(bundle).lexically_normal().string();
  run["source_generator"] = manifest.generator;
  run["what"] = "full relight from scene.bin: lightmaps, probes and voxel exitance recomputed; input lightmaps not read";
  run["device"] = integrator->device_description();
  run["spp"] = lighting.spp;
  run["seed"] = lighting.seed;
  run["time_budget_seconds"] = lighting.time_budget_seconds;
  run["rays"] = estimate.rays;
  run["rays_per_second"] = estimate.seconds > 0 ? double(estimate.rays) / estimate.seconds : 0.0;
  run["probe_rays"] = probe_estimate.rays;
  run["estimated_relative_error"] = relative_error_count ? relative_error_sum / double(relative_error_count) : 0.0;
  run["live_texels"] = persisted.gbuffer.texels.size();
  run["lighting_seconds"] = estimate.seconds;
  if (options.stage_statistics) run["stages"] = stages;
  if (options.traversal_rays > 0)
    run["traversal_only_rays_per_second"] = integrator->measure_incoherent_traversal(options.traversal_rays);
  run["nonfinite_samples"] = estimate.nonfinite_samples + probe_estimate.nonfinite_samples;

  // The pages as assembled now, under the file names the manifest gave them.
  if (pages.size() != manifest.pages.size())
    throw RelightInputError((bundle / "manifest.json").string() + ": pages: " + std::to_string(manifest.pages.size()) +
                            " listed, scene.bin's atlas has " + std::to_string(pages.size()));
  for (size_t p = 0; p < pages.size(); ++p) {
    manifest.pages[p].width = uint32_t(pages[p].width);
    manifest.pages[p].height = uint32_t(pages[p].height);
    manifest.pages[p].channels.clear();
    for (const auto& [name, data] : pages[p].channels) manifest.pages[p].channels.push_back(name);
  }
  manifest.generator = "exitance-relight 0.1.0";
  formats::BakeSettings& settings = manifest.settings.emplace(baked);
  settings.backend = "vulkan";
  settings.spp = lighting.spp;
  settings.seed = lighting.seed;
  settings.time_budget_seconds = lighting.time_budget_seconds;
  if (has_svo) {
    manifest.svo->vdb.clear();
    manifest.svo->vdb_note = "radiance.vdb is an inspection export of bake; exitance-relight does not write it";
  }
  manifest.relight_json = run.dump();
  const std::string manifest_text = formats::write_bundle_manifest(manifest);

  write_bundle_atomically(out, [&](const fs::path& dir) {
    for (size_t p = 0; p < pages.size(); ++p)
      formats::write_lightmap_exr((dir / manifest.pages[p].file).string(), pages[p]);
    if (has_probes) formats::write_probes_file((dir / manifest.probes->file).string(), persisted.probes);
    if (has_svo) formats::write_svo_file((dir / manifest.svo->file).string(), svo);
    formats::write_scene_file((dir / manifest.scene->file).string(), scene_file);
    std::ofstream file(dir / "manifest.json");
    file << manifest_text;
    if (!file) throw std::runtime_error("cannot write " + (dir / "manifest.json").string());
  });
  lap("write");
  run["seconds"] = seconds;
  run["output"] = fs::absolute(out).string();
  return run;
}

}  // namespace exitance
