#include "exitance/runtime/relight/relight.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>

#include "exitance/formats/bundle_manifest.h"
#include "exitance/formats/probes_file.h"
#include "exitance/formats/scene_file.h"
#include "exitance/formats/svo_file.h"
#include "exitance/runtime/bundle/bundle_directory.h"
#include "exitance/runtime/bundle/lightmap_assembly.h"
#include "exitance/runtime/bundle/probe_results.h"
#include "exitance/runtime/bundle/texel_exitance.h"
#include "exitance/runtime/vulkan/validation_messages.h"

namespace exitance {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

// Mean over live texels with signal of the relative standard error of the luminance (the
// manifest's estimated_relative_error, as bake reports it).
double mean_relative_error(const LightmapEstimate& estimate) {
  double sum = 0;
  size_t count = 0;
  for (size_t i = 0; i < estimate.texels.size(); ++i) {
    const float mean = luminance(estimate.mean_total(i));
    const float se = std::sqrt(luminance(estimate.variance_of_mean(i)));
    if (mean > 0) sum += se / mean, ++count;
  }
  return count ? sum / double(count) : 0.0;
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
  if (!(options.time_budget_seconds >= 0) || !(options.frame_budget_ms >= 0))
    throw RelightInputError("--time and --budget-ms must not be negative");

  const fs::path bundle(options.bundle);
  const fs::path out = options.output.empty() ? bundle : fs::path(options.output);
  report("load", 0, 0);
  RefreshSessionOptions session_options;
  session_options.seed = options.seed;
  session_options.device.device_index = options.device_index;
  session_options.device.validation = options.validation;
  session_options.device.collect_stage_statistics = options.stage_statistics;
  auto validation = std::make_shared<ValidationMessages>();
  if (options.validation) session_options.device.on_validation_message = ValidationMessages::collector(validation);
  const std::unique_ptr<RefreshSession> session = RefreshSession::open(options.bundle, session_options);
  formats::BundleManifest manifest = session->manifest();
  const formats::BakeSettings baked = manifest.settings.value_or(formats::BakeSettings{});
  lap("load");

  // The sample cap: --spp, else the bake's unless a time budget bounds the run.
  const uint32_t spp = options.spp ? *options.spp : (options.time_budget_seconds > 0 ? 0u : baked.spp);
  const bool bounded = spp > 0 || options.time_budget_seconds > 0 || options.frames > 0;
  if (!bounded) throw RelightInputError("--spp 0 needs --time or --frames");
  if (spp == 0 && options.frame_budget_ms == 0 && options.time_budget_seconds == 0)
    throw RelightInputError("--spp 0 with --frames needs --budget-ms or --time");

  // Frames: each a refresh call within the per-frame budget and what is left of --time.
  const auto lighting_start = Clock::now();
  json frames = json::array();
  uint64_t rays = 0;
  for (uint32_t frame = 0; options.frames == 0 || frame < options.frames; ++frame) {
    RefreshBudget budget;
    budget.max_samples_per_texel = spp;
    budget.milliseconds = options.frame_budget_ms;
    if (options.time_budget_seconds > 0) {
      const double left_ms = options.time_budget_seconds * 1e3 -
                             std::chrono::duration<double, std::milli>(Clock::now() - lighting_start).count();
      if (left_ms <= 0) break;
      budget.milliseconds = budget.milliseconds > 0 ? std::min(budget.milliseconds, left_ms) : left_ms;
    }
    const RefreshReport r = session->refresh(budget);
    rays += r.rays;
    if (options.frames > 0) {
      // Per-frame figures cost a read-back of the sums, outside the frame's time.
      const double error = RefreshSession::estimated_relative_mse(session->lightmap());
      frames.push_back({{"frame", frame}, {"milliseconds", r.milliseconds}, {"rays", r.rays},
                        {"samples_added", r.samples_added}, {"samples_per_texel", r.samples_per_texel},
                        {"estimated_relative_mse", std::isfinite(error) ? json(error) : json(nullptr)}});
    }
    const double fraction = spp ? double(r.samples_per_texel) / spp
                                : options.frames ? double(frame + 1) / options.frames : 0.0;
    report("lighting", std::min(1.0, fraction), rays);
    if (r.capped) break;
  }
  const double lighting_seconds = std::chrono::duration<double>(Clock::now() - lighting_start).count();
  const LightmapEstimate estimate = session->lightmap();
  lap("lighting");
  json stages = json::array();
  if (options.stage_statistics)
    for (const VulkanStageStatistics& s : session->integrator().stage_statistics())
      stages.push_back({{"stage", s.stage}, {"gpu_seconds", s.seconds}, {"items", s.items}, {"rays", s.rays},
                        {"lane_efficiency", s.lane_efficiency}});

  PersistedScene persisted = session->persisted();
  ProbeEstimate probe_estimate;
  const bool has_probes = persisted.has_probe_grid() && manifest.probes.has_value();
  if (has_probes) {
    report("probes", 0, 0);
    std::vector<size_t> traced;
    for (size_t i = 0; i < persisted.probes.probes.size(); ++i)
      if (formats::probe_is_usable(persisted.probes.probes[i])) traced.push_back(i);
    probe_estimate = session->probe_estimate(baked.probe_spp);
    store_probe_radiance(persisted.probes, traced, probe_estimate, baked.probe_dering_window);
    lap("probes");
  }
  validation->throw_if_any();

  std::optional<formats::SparseVoxelOctree> svo;
  if (session->svo()) {
    report("exitance", 0, 0);
    svo = *session->svo();
    fill_svo_exitance(*svo, persisted.scene, persisted.gbuffer, estimate);
    lap("exitance");
  }

  report("write", 0, 0);
  AssemblyOptions assembly;
  assembly.bounce_layers = manifest.has_bounce_layers();
  assembly.dilation_texels = std::max(2, int(baked.padding) * 2);
  const std::vector<formats::LightmapImage> pages = assemble_lightmap_pages(persisted.gbuffer, estimate, assembly);

  VulkanIntegrator& integrator = session->integrator();
  json run;
  run["tool"] = "exitance-relight";
  run["source_bundle"] = fs::absolute(bundle).lexically_normal().string();
  run["source_generator"] = manifest.generator;
  run["what"] = "full relight from scene.bin: lightmaps, probes and voxel exitance recomputed; input lightmaps not read";
  run["device"] = integrator.device_description();
  run["spp"] = integrator.progressive_samples();
  run["seed"] = session->settings().seed;
  run["time_budget_seconds"] = options.time_budget_seconds;
  if (options.frame_budget_ms > 0) run["frame_budget_ms"] = options.frame_budget_ms;
  run["rays"] = estimate.rays;
  run["rays_per_second"] = lighting_seconds > 0 ? double(estimate.rays) / lighting_seconds : 0.0;
  run["probe_rays"] = probe_estimate.rays;
  run["estimated_relative_error"] = mean_relative_error(estimate);
  run["estimated_relative_mse"] = RefreshSession::estimated_relative_mse(estimate);
  run["live_texels"] = persisted.gbuffer.texels.size();
  run["lighting_seconds"] = lighting_seconds;
  if (options.stage_statistics) run["stages"] = stages;
  if (options.traversal_rays > 0)
    run["traversal_only_rays_per_second"] = integrator.measure_incoherent_traversal(options.traversal_rays);
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
  settings.spp = integrator.progressive_samples();
  settings.seed = session->settings().seed;
  settings.time_budget_seconds = options.time_budget_seconds;
  if (svo) {
    manifest.svo->vdb.clear();
    manifest.svo->vdb_note = "radiance.vdb is an inspection export of bake; exitance-relight does not write it";
  }
  manifest.relight_json = run.dump();
  const std::string manifest_text = formats::write_bundle_manifest(manifest);

  write_bundle_atomically(out, [&](const fs::path& dir) {
    for (size_t p = 0; p < pages.size(); ++p)
      formats::write_lightmap_exr((dir / manifest.pages[p].file).string(), pages[p]);
    if (has_probes) formats::write_probes_file((dir / manifest.probes->file).string(), persisted.probes);
    if (svo) formats::write_svo_file((dir / manifest.svo->file).string(), *svo);
    formats::write_scene_file((dir / manifest.scene->file).string(), session->scene_file());
    std::ofstream file(dir / "manifest.json");
    file << manifest_text;
    if (!file) throw std::runtime_error("cannot write " + (dir / "manifest.json").string());
  });
  lap("write");
  run["seconds"] = seconds;
  run["output"] = fs::absolute(out).string();
  if (options.frames > 0) run["frames"] = frames;
  return run;
}

}  // namespace exitance
