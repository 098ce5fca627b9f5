#include "exitance/bake/command/bake_pipeline.h"

#include <algorithm>
#include <fstream>
#include <future>
#include <iterator>
#include <filesystem>
#include <optional>
#include <type_traits>

#include "exitance/bake/bundle/write_bundle.h"
#include "exitance/runtime/bundle/indirect_denoise.h"
#include "exitance/bake/cache/bake_cache_key.h"
#include "exitance/bake/cache/bundle_cache.h"
#include "exitance/bake/cache/sha256_stream.h"
#include "exitance/bake/command/backend_choice.h"
#include "exitance/bake/command/bake_stages.h"
#include "exitance/bake/command/automatic_integrator.h"
#include "exitance/bake/command/cached_offline_stages.h"
#include "exitance/formats/bundle_manifest.h"
#include "exitance/bake/input_error.h"
#include "exitance/runtime/core/work_share.h"
#include "exitance/runtime/stage_clock.h"

namespace exitance {

namespace {

using json = nlohmann::json;

// stats.seconds: one lap per stage, each from the end of the stage before, so the laps add up to
// the whole run.
class StageTimer {
 public:
  template <class Stage>
  auto time(const char* stage_name, Stage&& stage) -> decltype(stage()) {
    if constexpr (std::is_void_v<decltype(stage())>) {
      stage();
      seconds_[stage_name] = clock_.lap();
    } else {
      auto result = stage();
      seconds_[stage_name] = clock_.lap();
      return result;
    }
  }
  const json& seconds() const { return seconds_; }

 private:
  StageClock clock_;
  json seconds_ = json::object();
};

json run_report(const WrittenBundle& bundle, const json& seconds) {
  json report = bundle.stats;
  report["seconds"] = seconds;
  report["output"] = std::filesystem::absolute(bundle.folder).string();
  report["pages"] = bundle.pages;
  return report;
}

// The stored manifest with stats.cache saying it was reused (the rest of its stats describe the
// bake that computed it).
std::string mark_reused(const std::string& manifest_text, const std::string& key) {
  formats::BundleManifest manifest = formats::parse_bundle_manifest(manifest_text, "manifest.json");
  json stats = manifest.stats_json.empty() ? json::object() : json::parse(manifest.stats_json);
  json& cache = stats["cache"];
  cache["reused"] = true;
  cache["key"] = key;
  // Nothing ran this time: every stage the stored bake cached is reused.
  if (cache.contains("stages"))
    for (auto& outcome : cache["stages"]) outcome = "reused";
  manifest.stats_json = stats.dump();
  return formats::write_bundle_manifest(manifest);
}

// Warnings of the stored bake not given again by this run's import (which ran), in order.
void repeat_stored_warnings(const std::vector<std::string>& stored, Diagnostics& diagnostics) {
  std::vector<std::string> given = diagnostics.warnings;
  for (const std::string& w : stored) {
    auto found = std::find(given.begin(), given.end(), w);
    if (found != given.end()) {
      given.erase(found);
      continue;
    }
    diagnostics.warn(w);
  }
}

// stats.ranks and stats.rank_work (docs/bundle.md) from every rank's work.
json distribution_json(const std::vector<RankWork>& work) {
  json ranks = json::array();
  for (const RankWork& w : work)
    ranks.push_back({{"texel_samples", w.texel_samples},
                     {"probe_samples", w.probe_samples},
                     {"rays", w.rays},
                     {"seconds", w.seconds}});
  return {{"ranks", work.size()}, {"rank_work", ranks}};
}

// Tests: the rank named by EXITANCE_TEST_FAIL_RANK fails before lighting while the others wait in
// the lighting stage's first exchange (a rank that dies must end the job, not hang it).
void fail_here_if_asked(const WorkShare& share) {
  const char* rank = std::getenv("EXITANCE_TEST_FAIL_RANK");
  if (rank && std::to_string(share.rank()) == rank)
    throw std::runtime_error("rank " + std::string(rank) + " failed on purpose (EXITANCE_TEST_FAIL_RANK)");
}

}  // namespace

json run_bake(const BakeOptions& options, Diagnostics& diagnostics) {
  // Under mpirun (work_share.h) every rank runs the offline stages (replicated) and lights its share;
  // rank 0 alone uses the caches and writes. One process: share null.
  WorkShare* share = distributed(options.lighting.work_share);
  const bool writer = !share || share->rank() == 0;
  // Offline stage (DESIGN §1): scene, atlas, texel G-buffer, the BVHs, the backend that will light them.
  StageTimer clock;
  std::vector<MeshWithoutLightmapUvs> without_lightmap_uvs;
  Scene imported = clock.time("import", [&] { return import_stage(options, diagnostics, without_lightmap_uvs); });
  const std::string input_sha256 = sha256_of_file(options.input);  // the manifest's, and the cache key's

  // A bake of the same input with the same options and program is in the cache: reuse it. The key is
  // taken before UV generation, which it determines (the scene, the options and the program).
  std::optional<BundleCache> cache;
  std::string cache_key;
  std::optional<json> reused;
  if (!options.cache_directory.empty()) {
    cache.emplace(options.cache_directory);
    reused = clock.time("cache", [&]() -> std::optional<json> {
      options.announce_stage("cache");
      cache_key =
          bake_cache_key(imported, options, input_sha256, backend_candidates(options.backend));
      std::vector<std::string> stored_warnings;
      const std::filesystem::path out = bundle_folder(options);
      auto edit = [&](const std::string& text) { return mark_reused(text, cache_key); };
      if (!cache->restore(cache_key, out, edit, stored_warnings, diagnostics)) return std::nullopt;
      repeat_stored_warnings(stored_warnings, diagnostics);
      std::ifstream in(out / "manifest.json");
      const formats::BundleManifest manifest = formats::parse_bundle_manifest(
          std::string(std::istreambuf_iterator<char>(in), {}), (out / "manifest.json").string());
      return json{{"stats", json::parse(manifest.stats_json)}, {"pages", manifest.pages.size()}};
    });
  }
  // Under mpirun only rank 0 has a cache: the others learn here whether it reused a bundle (and stop).
  if (share && agreed(*share, uint8_t(reused ? 1 : 0)) && !writer) return json{{"rank", share->rank()}};
  if (reused) {
    if (!options.write_gltf.empty()) {  // the UVs again (their warnings were repeated from the cache)
      Diagnostics repeated;
      write_gltf_stage(uv_generation_stage(imported, without_lightmap_uvs, options, repeated), options, diagnostics);
    }
    return run_report(WrittenBundle{bundle_folder(options), (*reused)["pages"].get<size_t>(), (*reused)["stats"]},
                      clock.seconds());
  }
  std::vector<MeshUvReport> generated_uvs;
  if (!without_lightmap_uvs.empty())
    generated_uvs = clock.time("uv_generation", [&] {
      return uv_generation_stage(imported, without_lightmap_uvs, options, diagnostics);
    });
  // Each offline stage's products come from the per-stage cache when its inputs are unchanged.
  CachedOfflineStages stages(imported, options);
  const AtlasLayout layout = clock.time("layout", [&] { return stages.layout(imported, diagnostics); });
  TexelGBuffer gbuffer = clock.time("raster", [&] { return stages.raster(imported, layout, diagnostics); });
  const SceneForLighting scene =
      clock.time("bvh", [&] { return build_lighting_scene_stage(std::move(imported), options); });
  const std::shared_ptr<const Integrator> backend =
      clock.time("backend", [&] { return backend_stage(scene, options, diagnostics); });
  // --integrator auto becomes path or bounces here, where the backend is known; every later stage
  // (lighting, the manifest) sees the decided integrator.
  // The ranks exchange as their backend does (the CPU after every pass, Vulkan at the end): all must
  // have the same one (a rank whose GPU failed and fell back to the CPU ends the job).
  if (share && agreed(*share, uint8_t(backend->backend_name() == "vulkan")) != (backend->backend_name() == "vulkan"))
    throw std::runtime_error("rank " + std::to_string(share->rank()) + " runs the " + backend->backend_name() +
                             " backend, rank 0 another: under mpirun every rank must light on the same backend");
  const BakeOptions decided = with_integrator_decided(options, *backend);
  if (share && backend->backend_name() == "cpu" && decided.lighting.integrator == IntegratorMode::Path &&
      decided.lighting.target_relative_error > 0)
    throw InputError(options.input, "--target-error",
                     "on the CPU backend path tracing plans each texel's samples in one process; under mpirun use "
                     "--integrator bounces");
  const size_t unoccluded = clock.time("unocclude", [&] { return stages.unocclude(scene, gbuffer, layout, diagnostics); });
  const GeometryCheckReport geometry =
      clock.time("checks", [&] { return stages.checks(scene, gbuffer, diagnostics); });
  const SealedTexels sealed =
      clock.time("sealed_texels", [&] { return stages.sealed_texels(scene, gbuffer, geometry, diagnostics); });

  // Voxelize and place probes before lighting, so a bad --voxel-resolution or --probes fails before
  // the long stage.
  std::optional<VoxelizedScene> voxels;
  if (options.svo_enabled)
    voxels = clock.time("voxelize", [&] { return stages.voxelize(*scene.scene, layout, diagnostics); });
  std::optional<ProbePlacement> probes;
  if (options.probes_enabled)
    probes = clock.time("probe_placement",
                        [&] { return stages.place_probes(scene, voxels ? &*voxels : nullptr, diagnostics); });

  // Lighting stage (runtime/): probes, texels, their exitance into the octree. A --time budget covers
  // probes and texels: the probes go first with at most kProbeShareOfTimeBudget of it (and at most
  // --probe-spp), the texels get what the probes left.
  std::optional<ProbeEstimate> probe_lighting;
  BakeOptions lighting_options = decided;
  // SVO guiding builds its fields over the octree voxelized above (main refuses it without one).
  if (voxels) lighting_options.lighting.guiding_octree = &voxels->svo;
  const double budget = options.lighting.time_budget_seconds;
  // Where --guiding auto may measure light subpaths (the backend says where), the probes follow the
  // texels' verdict (probes_follow_texels): they are lit after the texels, with what a budget leaves.
  const bool probes_after_texels = probes && !share && backend->auto_guiding_may_measure_light_subpaths(decided.lighting);
  if (probes && !probes_after_texels) {
    const double probe_budget = budget > 0 ? kProbeShareOfTimeBudget * budget : 0.0;
    probe_lighting = clock.time(
        "probes", [&] { return probe_lighting_stage(*backend, *probes, decided, diagnostics, probe_budget); });
    // Never 0 (= no budget): a budget the probes used up leaves the texels one pass.
    if (budget > 0) lighting_options.lighting.time_budget_seconds = std::max(1e-3, budget - probe_lighting->seconds);
  }
  if (probes_after_texels && budget > 0) lighting_options.lighting.time_budget_seconds = (1.0 - kProbeShareOfTimeBudget) * budget;
  if (share) fail_here_if_asked(*share);
  LightmapEstimate lightmap =
      clock.time("lighting", [&] {
        return lighting_stage(*backend, gbuffer, options.skip_sealed_texels ? &sealed : nullptr, lighting_options,
                              diagnostics);
      });
  if (probes_after_texels) {
    const BakeOptions probe_options = probes_follow_texels(decided, lightmap);
    // Never 0 (= no budget): texels that used it up leave the probes one pass.
    const double probe_budget = budget > 0 ? std::max(1e-3, budget - lightmap.seconds) : 0.0;
    probe_lighting = clock.time(
        "probes", [&] { return probe_lighting_stage(*backend, *probes, probe_options, diagnostics, probe_budget); });
  }
  std::optional<IndirectDenoiseReport> denoised;
  if (options.denoise && writer) {
    options.announce_stage("denoise");
    denoised.emplace();
    lightmap = clock.time("denoise", [&] {
      return denoise_indirect(lightmap, gbuffer, IndirectDenoiseSettings{.radius = options.denoise_radius}, &*denoised);
    });
  }
  std::optional<json> distribution;
  if (options.lighting.work_share) distribution = distribution_json(gather_rank_work(*options.lighting.work_share));
  if (!writer) return json{{"rank", share->rank()}};
  // scene.bin's bytes and the octree's exitance read only finished products and are serial work
  // (1.0-1.2 cores busy), as the pages' compression leaves a core part idle (1.6 of 2): each runs on a
  // thread of its own from here, beside the other and the write, which waits for them where it needs
  // them. Their seconds are their threads' own and overlap the `write` lap (docs/bundle.md). Neither
  // reports progress (the write does).
  BakeOptions quiet = options;
  quiet.progress = nullptr;
  double scene_file_seconds = 0, exitance_seconds = 0;
  std::shared_future<PersistedSceneFile> scene_file =
      std::async(std::launch::async, [&] {
        StageClock own;
        PersistedSceneFile file = scene_file_stage(scene, gbuffer, layout, probes ? &*probes : nullptr);
        scene_file_seconds = own.lap();
        return file;
      }).share();
  std::shared_future<void> exitance;
  if (voxels)
    exitance = std::async(std::launch::async, [&] {
                 StageClock own;
                 exitance_stage(*voxels, scene, gbuffer, lightmap, quiet);
                 exitance_seconds = own.lap();
               }).share();
  // stats.seconds with the two threads' times, once they are done.
  auto seconds_with_beside = [&] {
    json seconds = clock.seconds();
    seconds["scene_file"] = scene_file_seconds;
    if (voxels) seconds["exitance"] = exitance_seconds;
    return seconds;
  };

  // Bundle: everything the stages produced, written at once.
  const BakeResults results{.scene = *scene.scene,
                            .layout = layout,
                            .gbuffer = gbuffer,
                            .unoccluded_texels = unoccluded,
                            .geometry = geometry,
                            .backend = *backend,
                            .voxels = voxels ? &*voxels : nullptr,
                            .probes = probes ? &*probes : nullptr,
                            .lightmap = lightmap,
                            .probe_lighting = probe_lighting ? &*probe_lighting : nullptr,
                            .scene_file = scene_file,
                            .exitance = exitance,
                            .input_sha256 = input_sha256,
                            .generated_uvs = &generated_uvs,
                            .sealed = &sealed,
                            .sealed_skipped = options.skip_sealed_texels,
                            .stage_cache = cache ? &stages.outcomes() : nullptr,
                            .distribution = distribution ? &*distribution : nullptr,
                            .denoise = denoised ? &*denoised : nullptr};
  WrittenBundle bundle =
      clock.time("write", [&] { return write_bundle_stage(results, seconds_with_beside, diagnostics, decided); });
  if (cache) {
    clock.time("cache_store", [&] { cache->store(cache_key, bundle.folder, diagnostics.warnings, diagnostics); });
    bundle.stats["cache"]["reused"] = false;  // its "stages" are in the manifest already
    bundle.stats["cache"]["key"] = cache_key;
  }
  // After the bundle, so a failed bake writes neither.
  if (!options.write_gltf.empty()) write_gltf_stage(generated_uvs, options, diagnostics);
  json seconds = seconds_with_beside();
  // --preview runs inside the write stage; the report shows its own time too, from the manifest.
  if (options.preview) seconds["preview"] = bundle.stats["seconds"]["preview"];
  return run_report(bundle, seconds);
}

}  // namespace exitance
