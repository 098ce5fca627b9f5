#include "exitance/runtime/refresh/refreshed_bundle.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <optional>

#include "exitance/formats/bundle_manifest.h"
#include "exitance/formats/probes_file.h"
#include "exitance/formats/scene_file.h"
#include "exitance/formats/svo_file.h"
#include "exitance/runtime/bundle/bundle_directory.h"
#include "exitance/runtime/bundle/light_layer_pages.h"
#include "exitance/runtime/bundle/light_paths_report.h"
#include "exitance/runtime/bundle/lightmap_assembly.h"
#include "exitance/runtime/bundle/probe_results.h"
#include "exitance/runtime/bundle/seam_stage.h"
#include "exitance/runtime/bundle/texel_exitance.h"
#include "exitance/runtime/refresh/bundle_light_layers.h"
#include "exitance/runtime/stage_clock.h"

namespace exitance {

namespace fs = std::filesystem;
using json = nlohmann::json;

json write_refreshed_bundle(RefreshSession& session, const std::string& output, json report,
                            const StageProgress& progress, const std::function<void()>& check_before_write) {
  StageClock clock;
  json seconds = json::object();
  auto stage = [&](const char* name) {
    if (progress) progress(name, 0, 0);
  };
  const fs::path bundle(session.bundle());
  formats::BundleManifest manifest = session.manifest();
  const formats::BakeSettings baked = manifest.settings.value_or(formats::BakeSettings{});
  const PersistedScene& persisted = session.persisted();
  // What does not depend on the lighting starts at once, each on its own thread beside the read-back,
  // the probes and the pages (the whole call was these stages one after another): scene.bin's
  // encoding and the seams' detection read only the scene. Nothing below writes what they read.
  std::future<std::vector<uint8_t>> scene_encoding =
      std::async(std::launch::async, [&session] { return formats::encode_scene(session.scene_file()); });
  const int dilation_texels = session.page_dilation_texels();
  const bool stitches = bundle_stitches_seams(manifest.stats_json);
  std::future<std::unique_ptr<BundleSeamStage>> seam_detection = std::async(std::launch::async, [&persisted, dilation_texels, stitches] {
    return std::make_unique<BundleSeamStage>(persisted.scene, persisted.atlas, dilation_texels, stitches);
  });
  // With light layers split by light where the session has them (docs/bundle.md "Light layers").
  // Not when the indirect light is filtered: light layers hold no split into direct and indirect.
  const int denoise_radius = session.denoise_radius();
  std::optional<LightmapEstimate> by_light = denoise_radius > 0 ? std::nullopt : session.published_lightmap_by_light();
  const bool layers_split = by_light.has_value();
  std::optional<DeviceDenoiseCounts> denoised;
  LightmapEstimate estimate;
  if (by_light) {
    estimate = std::move(*by_light);
  } else if (denoise_radius > 0) {
    stage("denoise");
    estimate = session.shown_lightmap(&denoised.emplace());
    seconds["denoise"] = clock.lap();
  } else {
    estimate = session.published_lightmap();
  }
  by_light.reset();
  seconds["read_back"] = clock.lap();  // what the session shows, read from the device (not the probes' time)

  // The voxel exitance of what is published, on its own thread beside the probes and the pages.
  std::optional<formats::SparseVoxelOctree> svo;
  std::future<double> exitance;
  if (session.svo()) {
    stage("exitance");
    svo = *session.svo();
    exitance = std::async(std::launch::async, [&] {
      StageClock own;
      fill_svo_exitance(*svo, persisted.scene, persisted.gbuffer, estimate);
      return own.lap();
    });
  }

  // Read in place; only the probes are rewritten (a copy of the whole scene and G-buffer cost 0.11 s
  // at 478 k texels on 2 cores).
  formats::ProbeGrid probes;
  ProbeEstimate probe_estimate;
  const bool has_probes = persisted.has_probe_grid() && manifest.probes.has_value();
  if (has_probes) {
    stage("probes");
    if (session.refreshes_probes()) {
      // What the refreshed probes show, as the pages hold what texels show (docs/runtime.md "Probes").
      probes = session.published_probes();
    } else {
      std::vector<size_t> traced;
      probes = persisted.probes;
      for (size_t i = 0; i < probes.probes.size(); ++i)
        if (formats::probe_is_usable(probes.probes[i])) traced.push_back(i);
      probe_estimate = session.probe_estimate(baked.probe_spp);
      store_probe_radiance(probes, traced, probe_estimate, baked.probe_dering_window);
    }
    seconds["probes"] = clock.lap();
  }

  stage("write");
  AssemblyOptions assembly;
  assembly.bounce_layers = manifest.has_bounce_layers();
  assembly.dilation_texels = dilation_texels;
  // Each page assembled, its seams stitched as `bake` stitched them (seam_stage.h; only measured where
  // it ran --seams off) and written before the next, in one image whose arrays each page reuses (as
  // bake's write_bundle_stage; holding every page at once was the most of the assembly's time).
  const LightmapPageAssembler assembler(persisted.gbuffer, estimate, assembly);
  // Light layers (docs/bundle.md "Light layers"), where what is published keeps a split by light.
  std::vector<formats::LightmapImage> layer_pages;
  manifest.light_layers.reset();
  std::string light_layers_skipped = estimate.light_layers == 0 ? "the session keeps no light layers" : "";
  if (denoised) light_layers_skipped = "--denoise: light layers are not split into direct and indirect light";
  if (estimate.light_layers > 0 && !layers_split)
    light_layers_skipped = "what is published has no split by light (the baked lightmap without layers and too few refreshed samples to split it by)";
  if (light_layers_skipped.empty()) {
    const std::optional<BundleLightLayers> layout = bundle_light_layers(session.lighting_scene());
    if (!layout) {
      light_layers_skipped = "the edited lights share layers differently from the layout scene.bin gets";
    } else {
      layer_pages = assemble_light_layer_pages(persisted.gbuffer, estimate, layout->bundle_layer);
      formats::LightLayersInfo& info = manifest.light_layers.emplace();
      info.count = layout->count;
      info.punctual = layout->punctual;
      for (size_t p = 0; p < layer_pages.size(); ++p) info.files.push_back("light-layers-" + std::to_string(p) + ".exr");
    }
  }
  // The pages as assembled now (below), under the file names the manifest gave them.
  if (assembler.page_count() != manifest.pages.size())
    throw BundleInputError((bundle / "manifest.json").string() + ": pages: " + std::to_string(manifest.pages.size()) +
                           " listed, scene.bin's atlas has " + std::to_string(assembler.page_count()));

  VulkanIntegrator& integrator = session.integrator();
  report["tool"] = "exitance-relight";
  report["source_bundle"] = fs::absolute(bundle).lexically_normal().string();
  report["source_generator"] = manifest.generator;
  report["what"] = std::string(report.contains("edits") ? "scene.bin edited, then " : "") +
                   "full relight from scene.bin: lightmaps, probes and voxel exitance recomputed (probes as refreshed in frames, where they were); " +
                   (session.started_from_baked() ? "input lightmaps the starting state (shown until refreshed samples are better)"
                                                 : "input lightmaps not read");
  report["device"] = integrator.device_description();
  report["spp"] = session.samples_per_texel();
  report["seed"] = session.settings().seed;
  report["rays"] = estimate.rays;
  report["probe_rays"] = probe_estimate.rays;
  // "refreshed": probes.bin holds what the session's refreshed probes show; "whole run": a probe
  // bake of its own at the bake's probe spp.
  if (has_probes) report["probes_written"] = session.refreshes_probes() ? "refreshed" : "whole run";
  report["estimated_relative_error"] = estimate.mean_relative_standard_error();
  const double relative_mse = RefreshSession::estimated_relative_mse(estimate);
  report["estimated_relative_mse"] = std::isfinite(relative_mse) ? json(relative_mse) : json(nullptr);
  report["live_texels"] = persisted.gbuffer.texels.size();
  // As stats has them for a bake: what a later session needs to start from these pages
  // (refresh/baked_lightmap.h): the fewest samples of a texel and error.Y's floor.
  {
    uint64_t sum = 0;
    uint32_t least = estimate.texels.empty() ? 0 : ~0u, most = 0;
    for (const TexelAccumulator& t : estimate.texels) least = std::min(least, t.samples), most = std::max(most, t.samples), sum += t.samples;
    report["samples_per_texel"] = {{"min", least}, {"max", most},
                                   {"mean", estimate.texels.empty() ? 0.0 : double(sum) / double(estimate.texels.size())}};
    report["error"] = {{"floor", estimate.error_floor()}};
  }
  report["nonfinite_samples"] = estimate.nonfinite_samples + probe_estimate.nonfinite_samples;
  // A progressive refresh with light subpaths (RefreshSessionOptions::light_subpaths): the pools' totals.
  if (session.settings().light_subpaths && !report.contains("light_paths"))
    report["light_paths"] = light_paths_json(estimate);
  if (denoised)
    report["denoise"] = {{"radius", denoise_radius},
                         {"texels", denoised->texels},
                         {"mean_neighbours", denoised->texels > 0 ? double(denoised->neighbours) / double(denoised->texels) : 0.0},
                         {"seconds", seconds["denoise"]}};
  report["bundle_light_layers"] = manifest.light_layers ? json{{"count", manifest.light_layers->count}, {"written", true}}
                                                 : json{{"written", false}, {"why_not", light_layers_skipped}};

  manifest.generator = "exitance-relight 0.1.0";
  formats::BakeSettings& settings = manifest.settings.emplace(baked);
  settings.backend = "vulkan";
  settings.integrator = session.per_bounce() ? "bounces" : "path";
  settings.spp = session.samples_per_texel();
  settings.seed = session.settings().seed;
  settings.time_budget_seconds = report.value("time_budget_seconds", 0.0);
  settings.directional = estimate.has_sh1() ? "sh1" : "off";  // the session refreshes what the bake estimated
  if (svo) {
    manifest.svo->vdb.clear();
    manifest.svo->vdb_note = "radiance.vdb is an inspection export of bake; exitance-relight does not write it";
  }
  const std::vector<uint8_t> scene_bytes = scene_encoding.get();
  manifest.scene->bytes = scene_bytes.size();
  manifest.scene->format_version = formats::kSceneFormatVersion;  // a version 1 input is rewritten as the current one
  if (check_before_write) check_before_write();

  const fs::path out(output);
  try {
    write_bundle_atomically(out, [&](const fs::path& dir) {
      // scene.bin written on its own thread while the pages are assembled and compressed.
      std::future<void> scene_written = std::async(std::launch::async, [&] {
        std::ofstream scene_out(dir / manifest.scene->file, std::ios::binary);
        scene_out.write(reinterpret_cast<const char*>(scene_bytes.data()), std::streamsize(scene_bytes.size()));
        if (!scene_out) throw std::runtime_error("cannot write " + (dir / manifest.scene->file).string());
      });
      const std::unique_ptr<BundleSeamStage> seam_stage = seam_detection.get();
      BundleSeamStage& seams = *seam_stage;
      formats::LightmapImage page;
      for (size_t p = 0; p < manifest.pages.size(); ++p) {
        assembler.assemble(p, page);
        seams.page(p, page);
        manifest.pages[p].width = uint32_t(page.width);
        manifest.pages[p].height = uint32_t(page.height);
        manifest.pages[p].channels.clear();
        for (const auto& [name, data] : page.channels) manifest.pages[p].channels.push_back(name);
        formats::write_lightmap_exr((dir / manifest.pages[p].file).string(), page);
      }
      report["seams"] = seams.report();
      manifest.relight_json = report.dump();
      const std::string manifest_text = formats::write_bundle_manifest(manifest);
      for (size_t p = 0; p < layer_pages.size(); ++p)
        formats::write_lightmap_exr((dir / manifest.light_layers->files[p]).string(), layer_pages[p]);
      if (has_probes) formats::write_probes_file((dir / manifest.probes->file).string(), probes);
      if (svo) {
        seconds["exitance"] = exitance.get();  // its own time, beside the probes and the pages
        formats::write_svo_file((dir / manifest.svo->file).string(), *svo);
      }
      scene_written.get();
      std::ofstream file(dir / "manifest.json");
      file << manifest_text;
      if (!file) throw std::runtime_error("cannot write " + (dir / "manifest.json").string());
    });
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    throw BundleWriteError(e.what());
  }
  seconds["write"] = clock.lap();
  report["seconds"] = seconds;
  report["output"] = fs::absolute(out).string();
  return report;
}

}  // namespace exitance
