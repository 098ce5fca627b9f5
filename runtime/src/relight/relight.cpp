#include "exitance/runtime/relight/relight.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>

#include "exitance/runtime/bundle/bounce_statistics_report.h"
#include "exitance/runtime/bundle/emitter_guiding_report.h"
#include "exitance/runtime/bundle/guiding_auto_report.h"
#include "exitance/runtime/bundle/light_paths_report.h"
#include "exitance/formats/bundle_manifest.h"
#include "exitance/runtime/refresh/refreshed_bundle.h"
#include "exitance/runtime/stage_clock.h"
#include "exitance/runtime/vulkan/validation_messages.h"
#include "exitance/runtime/relight/one_rank_alone.h"

namespace exitance {

namespace fs = std::filesystem;
using json = nlohmann::json;

json relight_bundle(const RelightOptions& options) {
  using Clock = std::chrono::steady_clock;
  StageClock clock;
  json seconds = json::object();
  auto report = [&](const std::string& stage, double fraction, uint64_t rays) {
    if (options.progress) options.progress(stage, fraction, rays);
  };
  if (!(options.time_budget_seconds >= 0) || !(options.frame_budget_ms >= 0))
    throw RelightInputError("--time and --budget-ms must not be negative");
  const bool per_bounce = options.integrator == "bounces";
  if (!per_bounce && options.integrator != "path")
    throw RelightInputError("--integrator " + options.integrator + ": expected path or bounces");
  if (options.page_images && options.frames == 0)
    throw RelightInputError("--page-images reports per frame: it needs --frames");
  if (options.samples_before_edits > 0 && options.edits_file.empty())
    throw RelightInputError("--spp-before-edits refreshes before the edits: it needs --edits");
  if (per_bounce && (options.frames > 0 || options.frame_budget_ms > 0))
    throw RelightInputError("--integrator bounces runs the whole lightmap at once: --frames and --budget-ms need --integrator path");
  const bool guided = options.guiding == "grid" || options.guiding == "svo" || options.guiding == "auto";
  if (!guided && options.guiding != "off") throw RelightInputError("--guiding " + options.guiding + ": expected off, grid, svo or auto");
  if (guided && per_bounce) throw RelightInputError("--guiding " + options.guiding + " guides path tracing: it needs --integrator path");
  if (guided && (options.frames > 0 || options.frame_budget_ms > 0))
    throw RelightInputError("--guiding " + options.guiding + " runs the whole lightmap at once: --frames and --budget-ms need --guiding off");
  if (options.bounce_caches != "device" && options.bounce_caches != "host")
    throw RelightInputError("--bounce-caches " + options.bounce_caches + ": expected device or host");
  if (options.bounce_caches != "device" && !per_bounce)
    throw RelightInputError("--bounce-caches " + options.bounce_caches + " places the per-bounce mode's caches: it needs --integrator bounces");
  if (options.emitter_guiding != "off" && options.emitter_guiding != "on")
    throw RelightInputError("--emitter-guiding " + options.emitter_guiding + ": expected off or on");
  const bool emitter_guided = options.emitter_guiding == "on";
  if (emitter_guided && (per_bounce || guided || options.frames > 0 || options.frame_budget_ms > 0))
    throw RelightInputError("--emitter-guiding on guides path tracing of the whole lightmap in one run: it takes no "
                            "--integrator bounces, --guiding, --frames or --budget-ms");
  if (options.light_paths != "off" && options.light_paths != "on")
    throw RelightInputError("--light-paths " + options.light_paths + ": expected off or on");
  const bool light_paths = options.light_paths == "on";
  if (light_paths && (per_bounce || guided))
    throw RelightInputError("--light-paths on adds strategies to path tracing: it takes no --integrator bounces or --guiding");
  // With --time, --frames or --budget-ms, light paths refresh progressively as path tracing alone
  // does (RefreshSessionOptions::light_subpaths: the session's passes connect, edits keep their
  // rules); with --spp alone, or with --emitter-guiding on (a whole run itself), one whole run, bake
  // --backend vulkan --light-paths on's bit for bit.
  if (options.whole_run && (per_bounce || guided || options.frames > 0 || options.frame_budget_ms > 0))
    throw RelightInputError("--whole-run path traces the whole lightmap in one run: it takes no --frames, --budget-ms, --guiding "
                            "or --integrator bounces");
  const bool whole_run_light_paths =
      light_paths && (emitter_guided || options.whole_run ||
                      (options.frames == 0 && options.frame_budget_ms == 0 && options.time_budget_seconds == 0));
  const bool whole_run = options.whole_run;

  const bool share = options.share_ranks > 0;
  if (share) {
    if (options.share_rank < 0 || options.share_rank >= options.share_ranks)
      throw RelightInputError("--share " + std::to_string(options.share_rank) + "/" + std::to_string(options.share_ranks) +
                              ": expected R/N with 0 <= R < N");
    if (per_bounce || guided || emitter_guided || light_paths || whole_run || options.frames > 0 || options.frame_budget_ms > 0 || options.time_budget_seconds > 0 ||
        !options.edits_file.empty() || !options.output.empty() || !options.spp || *options.spp == 0)
      throw RelightInputError("--share measures one rank's share of path tracing at a fixed --spp: it takes no --integrator bounces, "
                              "--guiding, --emitter-guiding, --light-paths, --whole-run, --frames, --budget-ms, --time, --edits or -o (it writes nothing)");
  }
  const fs::path bundle(options.bundle);
  const fs::path out = options.output.empty() ? bundle : fs::path(options.output);
  report("load", 0, 0);
  RefreshSessionOptions session_options;
  session_options.seed = options.seed;
  session_options.start_from_baked = options.from_baked;
  session_options.priority_samples = options.priority_samples;
  // Light layers serve edits that come while frames refresh; a whole run after the edits (no
  // --frames, --budget-ms or --spp-before-edits) pays for them (11 % of its rays/s on the H200 at 22
  // layers: bench/results/light-layers.md) only to write them into the bundle (--light-layers).
  if (options.whole_run_light_layers && !options.light_layers)
    throw RelightInputError("--light-layers and --no-light-layers contradict each other");
  if (options.whole_run_light_layers && options.denoise_radius > 0)
    throw RelightInputError("--denoise filters the indirect light, which --light-layers do not keep apart from the direct: relight with one of them");
  session_options.light_layers = options.light_layers && (options.whole_run_light_layers || options.frames > 0 ||
                                                          options.frame_budget_ms > 0 || options.samples_before_edits > 0);
  // Probes are refreshed in frames (a whole run bakes them once, for the bundle it writes).
  session_options.refresh_probes = options.frames > 0 || options.frame_budget_ms > 0;
  session_options.light_subpaths = light_paths;
  session_options.device.device_index = options.device_index;
  session_options.device.validation = options.validation;
  session_options.device.collect_stage_statistics = options.stage_statistics;
  // lavapipe compiles each kernel at its first dispatch: 20-60 s with a cold shader cache.
  session_options.device.on_compile_progress = [&](double fraction) { report("compiling kernels", fraction, 0); };
  auto validation = std::make_shared<ValidationMessages>();
  if (options.validation) session_options.device.on_validation_message = ValidationMessages::collector(validation);
  const std::unique_ptr<RefreshSession> session = RefreshSession::open(options.bundle, session_options);
  if (options.guiding == "svo" && !session->svo())
    throw RelightInputError(options.bundle + ": --guiding svo reads the bundle's svo.bin, which it has none of (baked with --voxel-resolution none)");
  const formats::BakeSettings baked = session->manifest().settings.value_or(formats::BakeSettings{});
  if (options.denoise_radius > 0 && baked.directional != "off")
    throw RelightInputError(options.bundle + ": --denoise: the bundle has L1 (" + baked.directional +
                            ") layers, which are not split into direct and indirect light");
  // Frames then show the filtered light too (page images), as an engine's session would.
  session->set_denoise_radius(options.denoise_radius);
  seconds["load"] = clock.lap();
  const OpenTimings& opened = session->open_timings();
  seconds["load_split"] = {{"read", opened.read},     {"lighting_scene", opened.lighting_scene}, {"device", opened.device},
                           {"indices", opened.indices}, {"texels", opened.texels},               {"baked", opened.baked},
                           {"publish", opened.publish}};

  json edits_report;
  if (options.samples_before_edits > 0) {  // a session that has been refreshing when the edit comes
    report("refreshing before the edits", 0, 0);
    // With a frame budget, in frames of that budget (the pass costs the frames after the edits use
    // are then measured on frames like them); else in one call.
    // Frames go on while they add samples to texels or probes (a frame may spend its budget on probes alone).
    RefreshReport before;
    do before = session->refresh({options.frame_budget_ms, options.samples_before_edits});
    while (options.frame_budget_ms > 0 && !before.capped && (before.rays > 0 || before.probe_rays > 0));
    seconds["before_edits"] = clock.lap();
    edits_report["samples_before"] = before.samples_per_texel;
  }
  if (!options.edits_file.empty()) {
    report("edits", 0, 0);
    std::ifstream in(options.edits_file, std::ios::binary);
    if (!in) throw RelightInputError(options.edits_file + ": cannot read the edits file");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    try {
      const std::vector<SceneEdit> edits = parse_scene_edits(text, options.edits_file);
      const EditEffects effects = session->apply_edits(edits);
      edits_report.update({{"file", fs::absolute(options.edits_file).lexically_normal().string()},
                      {"edits", edits.size()},
                      {"moved_instances", effects.moved_instances},
                      {"moved_texels", effects.moved_texels},
                      {"lights", effects.lights},
                      {"materials", effects.materials},
                      {"sky", effects.sky},
                      // punctual lights whose change from the pre-edit lighting is estimated (0: restarted)
                      {"changed_lights", session->changed_lights()}});
      const EditTimings& t = session->last_edit_timings();
      // true: the edits only scaled lights, whose layers were scaled with 0 rays (no sample dropped)
      edits_report["scaled_light_layers"] = t.scaled_light_layers;
      edits_report["milliseconds"] = {{"scene", t.scene},     {"texels", t.texels},   {"near_texels", t.near_texels},
                                      {"uploads", t.uploads}, {"publish", t.publish}, {"restart", t.restart},
                                      {"device_wait", t.device_wait}};
      edits_report["device_submissions"] = t.device_submissions;
    } catch (const SceneEditError& e) {
      throw RelightInputError(e.what());
    }
    seconds["edits"] = clock.lap();
  }

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
  json bounces_report;  // the per-bounce mode's layers, stop and host seconds
  if (per_bounce) {
    report("lighting", 0, 0);
    try {
      const LightmapEstimate& run = session->bake_per_bounce(spp, options.time_budget_seconds, options.bounce_caches == "host");
      rays = run.rays;
      bounces_report = bounce_statistics_json(run.bounce_statistics);
    } catch (const std::invalid_argument& e) {
      throw RelightInputError(options.bundle + ": " + e.what());
    }
    report("lighting", 1, rays);
  }
  json guiding_auto_report;
  if (guided) {
    report("lighting", 0, 0);
    const GuidingMode mode = options.guiding == "svo" ? GuidingMode::Svo : options.guiding == "auto" ? GuidingMode::Auto : GuidingMode::Grid;
    const LightmapEstimate& run = session->bake_guided(spp, options.time_budget_seconds, 0.5f, mode);
    rays = run.rays;
    if (mode == GuidingMode::Auto) guiding_auto_report = guiding_auto_json(run, "vulkan");
    report("lighting", 1, rays);
  }
  // One path-traced run of the whole lightmap: --emitter-guiding on, or --light-paths on with --spp alone (or both).
  json emitter_guiding_report, light_paths_report;
  if (emitter_guided || whole_run_light_paths || whole_run) {
    report("lighting", 0, 0);
    const LightmapEstimate* run = nullptr;
    try {
      run = &session->bake_path(spp, options.time_budget_seconds, nullptr, emitter_guided, whole_run_light_paths);
    } catch (const std::invalid_argument& e) {  // e.g. the edits changed the emitters the guide was made for
      throw RelightInputError(options.bundle + ": " + e.what());
    }
    rays = run->rays;
    if (emitter_guided) emitter_guiding_report = emitter_guiding_json(run->emitter_guiding);
    if (whole_run_light_paths) light_paths_report = light_paths_json(*run);
    report("lighting", 1, rays);
  }
  uint64_t share_texels = 0;
  double share_passes_seconds = 0;
  if (share) {
    report("lighting", 0, 0);
    OneRankAlone rank_alone(options.share_rank, options.share_ranks);
    const LightmapEstimate& e = session->bake_path(spp, 0, &rank_alone);
    rays = e.rays;
    share_passes_seconds = e.seconds;
    // Every texel of the share takes all --spp samples (only rank 0 keeps per-texel sums).
    share_texels = rank_alone.work.texel_samples / spp;
    report("lighting", 1, rays);
  }
  for (uint32_t frame = 0; !per_bounce && !guided && !emitter_guided && !whole_run_light_paths && !whole_run && !share && (options.frames == 0 || frame < options.frames); ++frame) {
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
      json entry = {{"frame", frame}, {"milliseconds", r.milliseconds}, {"rays", r.rays},
                    {"samples_added", r.samples_added}, {"samples_per_texel", r.samples_per_texel}};
      if (r.probes_refreshed > 0 || r.probe_samples > 0)
        entry["probes"] = {{"refreshed", r.probes_refreshed}, {"rays", r.probe_rays}, {"samples", r.probe_samples}};
      if (options.frame_errors && session->refreshes_probes()) {
        const RefreshSession::ProbeErrors p = session->probe_errors();
        json& probes = entry["probes"];
        probes["showing_refreshed"] = p.showing_refreshed;
        probes["estimated_relative_mse"] = std::isfinite(p.estimated_relative_mse) ? json(p.estimated_relative_mse) : json(nullptr);
      }
      if (options.page_images) {  // what an engine's frame adds to hand the pages over on the device
        const auto images_start = Clock::now();
        session->publish_page_images(session->page_dilation_texels());
        entry["page_images_milliseconds"] = std::chrono::duration<double, std::milli>(Clock::now() - images_start).count();
        // The probes and the voxel exitance handed over on the device the same way, where the bundle has them.
        if (session->refreshes_probes()) {
          const auto probes_start = Clock::now();
          session->publish_probe_buffer();
          entry["probe_buffer_milliseconds"] = std::chrono::duration<double, std::milli>(Clock::now() - probes_start).count();
        }
        if (session->svo()) {
          const auto voxels_start = Clock::now();
          session->publish_voxel_exitance();
          entry["voxel_exitance_milliseconds"] = std::chrono::duration<double, std::milli>(Clock::now() - voxels_start).count();
        }
      }
      const LightmapEstimate now = options.frame_errors ? session->refreshed_lightmap() : LightmapEstimate{};
      if (options.frame_errors) {
        const double error = RefreshSession::estimated_relative_mse(now);
        entry["estimated_relative_mse"] = std::isfinite(error) ? json(error) : json(nullptr);
      }
      const std::vector<uint32_t>& near = session->texels_near_last_edit();
      if (options.frame_errors && !near.empty()) {
        // The texels the edit prioritized: their own error (null while one has fewer than 2 samples).
        LightmapEstimate subset;
        bool complete = true;
        for (uint32_t i : near) complete = complete && now.texels[i].samples >= 2, subset.texels.push_back(now.texels[i]);
        const double near_error = complete ? RefreshSession::estimated_relative_mse(subset) : INFINITY;
        entry["prioritized_texels"] = near.size();
        entry["prioritized_estimated_relative_mse"] = std::isfinite(near_error) ? json(near_error) : json(nullptr);
      }
      frames.push_back(entry);
    }
    const double fraction = spp ? double(r.samples_per_texel) / spp
                                : options.frames ? double(frame + 1) / options.frames : 0.0;
    report("lighting", std::min(1.0, fraction), rays);
    if (r.capped) break;
  }
  const double lighting_seconds = std::chrono::duration<double>(Clock::now() - lighting_start).count();
  seconds["lighting"] = clock.lap();
  json stages = json::array();
  if (options.stage_statistics)
    for (const VulkanStageStatistics& s : session->integrator().stage_statistics())
      stages.push_back({{"stage", s.stage}, {"gpu_seconds", s.seconds}, {"items", s.items}, {"rays", s.rays},
                        {"lane_efficiency", s.lane_efficiency}});

  json run;
  run["integrator"] = per_bounce ? "bounces" : "path";
  if (guided) run["guiding"] = options.guiding;
  if (whole_run) run["whole_run"] = true;  // --whole-run: one run as bake lights it, not refresh calls
  if (!guiding_auto_report.is_null()) run["guiding_auto"] = guiding_auto_report;  // bake's stats.guiding
  if (emitter_guided) run["emitter_guiding"] = emitter_guiding_report;
  if (whole_run_light_paths) run["light_paths"] = light_paths_report;  // else write_refreshed_bundle's, from the accumulation
  if (per_bounce) run["bounces"] = bounces_report;
  run["spp"] = session->samples_per_texel();
  // Light layers kept per texel (docs/runtime.md "Light layers"; 0: --no-light-layers or a whole run)
  run["light_layers"] = session->integrator().light_layers();
  run["time_budget_seconds"] = options.time_budget_seconds;
  if (options.frame_budget_ms > 0) run["frame_budget_ms"] = options.frame_budget_ms;
  run["lighting_seconds"] = lighting_seconds;
  run["rays_per_second"] = lighting_seconds > 0 ? double(rays) / lighting_seconds : 0.0;
  if (options.stage_statistics) run["stages"] = stages;
  if (!edits_report.is_null()) run["edits"] = edits_report;
  if (options.traversal_rays > 0)
    run["traversal_only_rays_per_second"] = session->integrator().measure_incoherent_traversal(options.traversal_rays);
  if (share) {
    run["share"] = {{"rank", options.share_rank}, {"ranks", options.share_ranks}, {"texels", share_texels},
                    {"passes_seconds", share_passes_seconds}};
    run["rays"] = rays;
    run["device"] = session->integrator().device_description();
    validation->throw_if_any();
    return run;
  }
  json written = write_refreshed_bundle(*session, out.string(), run, options.progress,
                                        [&] { validation->throw_if_any(); });
  for (auto& [stage, value] : written["seconds"].items()) seconds[stage] = value;
  written["seconds"] = seconds;
  if (options.frames > 0) written["frames"] = frames;
  return written;
}

}  // namespace exitance
