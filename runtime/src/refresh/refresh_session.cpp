#include "exitance/common/light_layers.h"
#include "exitance/common/path_sampler.h"
#include "exitance/common/texture_space_filter.h"
#include "exitance/runtime/refresh/refresh_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <cstring>
#include <limits>
#include <optional>

#include "exitance/formats/format_error.h"
#include "exitance/formats/probes_file.h"
#include "exitance/runtime/bundle/probe_results.h"
#include "published_probes.h"
#include "exitance/runtime/spherical_harmonics.h"
#include "exitance/runtime/bundle/texel_exitance.h"
#include "exitance/formats/scene_file.h"
#include "exitance/formats/svo_file.h"
#include "exitance/runtime/refresh/baked_lightmap.h"
#include "exitance/runtime/refresh/light_layer_edits.h"
#include "exitance/runtime/refresh/pass_cost.h"
#include "exitance/runtime/refresh/published_estimate.h"
#include "exitance/runtime/refresh/texel_grid.h"
#include "exitance/runtime/refresh/texels_near_change.h"
#include "exitance/runtime/refresh/unocclude_near_moved.h"

namespace exitance {

namespace fs = std::filesystem;

struct RefreshSession::State {
  std::string bundle;
  formats::BundleManifest manifest;
  // As read (encoding it again gives its bytes back); empty after an edit until asked for.
  mutable std::optional<formats::SceneFile> scene_file;
  // scene.bin's records as read, dropped by the first edit but freed by the next refresh call: at
  // 1 M texels freeing them took 1.2-1.5 ms, most of a light edit's scene step on the H200.
  std::optional<formats::SceneFile> stale_scene_file;
  PersistedScene persisted;
  std::optional<formats::SparseVoxelOctree> svo;
  // Its source is `persisted.scene` itself (not a copy): light and sky edits change both in place.
  std::shared_ptr<LightingScene> lighting;
  IntegratorSettings settings;
  std::unique_ptr<VulkanIntegrator> integrator;
  refresh::PassCost pass_cost;  // sizes passes to a millisecond budget (refresh/pass_cost.h)
  uint32_t priority_samples = 32;
  // The accumulation since the last edit, as lists of texels with their sample counts: after a
  // local edit, the texels near it first (until priority_samples), then the others until they
  // catch up, then all together. Each list's texels share one count, so sample indices stay those
  // of a bake.
  std::vector<uint32_t> near_texels, far_texels, all_texels;
  std::vector<uint32_t> last_edit_near;  // near_texels of the last edit, kept after the others caught up
  TexelGrid texel_grid;  // over persisted.gbuffer's texels: moved ones set aside, rebuilt when many are
  std::vector<uint8_t> near_marks;  // texels_near_change's scratch: a zero byte per texel
  // What an edit made in place needs without a pass over the scene: each instance's texels, where
  // each BVH leaf slot and node hangs, and the bounds of each instance's triangles (and of those in
  // no instance), whose union is the scene's bounds.
  InstanceTexels instance_texels;
  Bvh4Links bvh_links;
  std::vector<WorldBox> instance_boxes;
  WorldBox uninstanced_box;
  EditTimings edit_timings;
  OpenTimings open_timings;
  uint32_t near_samples = 0, far_samples = 0, all_samples = 0;
  // Texels [0, partial) of the list being refreshed have one sample more than its count: a sample
  // of the list under way, in passes over parts of it (refresh(): a budget shorter than a sample).
  size_t partial = 0;
  // What texels showed before the last edit (published_lightmap keeps it until the refreshed
  // estimate is better; published_estimate.h); at open, the bundle's baked lightmap. In device
  // memory (VulkanIntegrator::publish composes what is published there); shared with `base` when a
  // light edit starts a change estimate.
  std::shared_ptr<DeviceLightmap> previous;
  // After edits that changed punctual lights only: the estimate the accumulation's change is added
  // to (what was published before the first of them), the punctual lights as they were then, and
  // how many changed lights the accumulation estimates (0: the accumulation is E/pi itself).
  std::shared_ptr<DeviceLightmap> base;
  std::vector<GpuPunctualLight> base_lights;
  uint32_t changed_lights = 0;
  bool started_from_baked = false;  // previous was the bundle's baked lightmap at open
  // previous's light layers split its totals by light (false: the baked lightmap, whose bundle has
  // none, a change estimate's result, or anything published from them); meaningless without previous.
  bool previous_split_by_light = false;
  bool base_split_by_light = false;  // the same for base (a change estimate's changes go to their lights' layers)
  uint32_t proportional_split_samples = 256;  // RefreshSessionOptions::proportional_split_samples
  // Refreshed probes (RefreshSessionOptions::refresh_probes; docs/runtime.md "Probes"): per refreshed
  // probe its index in persisted.probes and what it showed before (at open the bundle's probes.bin),
  // shown until the refreshed estimate is the better by the publishing rule (published_probes.h;
  // where the kept value's variance is unknown, until it has probe_switch_samples); the bake's
  // probe_spp as the target; the last full batch and its time, which size a call's batch.
  std::vector<size_t> probe_grid_index;
  std::vector<KeptProbe> previous_probes;
  // While the lightmap estimates a change of punctual lights (`base`), the probes do too: what they
  // showed at its first edit, the base their sums' change is added to (published_probes.h); empty
  // otherwise.
  std::vector<KeptProbe> probe_base;
  bool previous_probes_uploaded = false;  // publish_probe_buffer's copies of them (and the base) are current
  bool voxel_deposits_current = false;    // publish_voxel_exitance's deposits are the texels' as they are
  uint32_t probe_switch_samples = 0;
  uint32_t probe_target = 0;
  float probe_dering = 0;
  double probe_budget_share = 0.25;
  size_t probe_last_batch = 0;    // probes in the last full batch of a call, and its milliseconds
  double probe_last_batch_ms = 0;
  int denoise_radius = 0;  // set_denoise_radius: 0, or the filter's window radius in texels
  // A bake_per_bounce(), bake_guided() or bake_path() result: lightmap() until the next restart, edit
  // or refresh.
  std::optional<LightmapEstimate> per_bounce;
  bool whole_run_path = false;    // per_bounce holds a bake_guided() or bake_path() result (path tracing)
  bool whole_run_guided = false;  // per_bounce holds a bake_guided() result

  // What a new accumulation (restart or change estimate) starts without: a whole run's result and
  // every texel list's samples.
  void clear_accumulation() {
    per_bounce.reset();
    whole_run_path = whole_run_guided = false;
    near_texels.clear();
    far_texels.clear();
    near_samples = far_samples = all_samples = 0;
    partial = 0;
  }
};

namespace {

void check_light_subpaths_per_sample(double per_sample, const std::string& what) {
  if (!(per_sample > 0 && per_sample <= 64))
    throw std::invalid_argument(what + ": " + std::to_string(per_sample) + " subpaths per texel sample is not in (0, 64]");
}

void check_denoise_radius(int radius, const IntegratorSettings& settings, const std::string& what) {
  if (radius < 0 || radius > kFilterMaxRadius)
    throw std::invalid_argument(what + ": radius " + std::to_string(radius) + " is not 0 (off) to " + std::to_string(kFilterMaxRadius));
  if (radius > 0 && settings.directional != DirectionalMode::Off)
    throw std::invalid_argument(what + ": the bundle has L1 (sh1) layers, which are not split into direct and indirect light");
}

// A whole run's time budget counts from the call, as bake's counts from its lighting stage: the
// integrator's setup (an emitter-guiding cache took 0.10 s of a 0.25 s budget on an H100) is spent
// from it, not beside it.
void budget_from_now(IntegratorSettings& settings) {
  if (!(settings.time_budget_seconds > 0) || settings.budget_clock) return;  // a caller's clock (tests) stays
  settings.budget_clock = [start = std::chrono::steady_clock::now()] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
}

// The session's scene as a lighting scene's source: persisted.scene itself, not owned (the
// session outlives its lighting scenes and integrator, State keeps it at one address).
std::shared_ptr<const Scene> scene_of(const RefreshSession::State& s) { return std::shared_ptr<const Scene>(std::shared_ptr<const Scene>{}, &s.persisted.scene); }

formats::BundleManifest read_manifest(const fs::path& bundle) {
  const fs::path path = bundle / "manifest.json";
  std::ifstream in(path, std::ios::binary);
  if (!in) throw BundleInputError(path.string() + ": cannot read the manifest (is " + bundle.string() + " a bundle?)");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    return formats::parse_bundle_manifest(text, path.string());
  } catch (const formats::FormatError& e) {
    throw BundleInputError(e.what());
  }
}

void index_for_edits(RefreshSession::State& s) {
  const Scene& scene = s.persisted.scene;
  s.instance_texels = InstanceTexels(s.persisted.gbuffer, scene.instances.size());
  try {
    s.bvh_links = link_bvh4(s.lighting->bvh, scene.triangle_count());
  } catch (const std::invalid_argument& e) {
    throw BundleInputError(s.bundle + ": scene.bin: BVH: " + e.what());
  }
  std::vector<uint8_t> instanced(scene.triangle_count(), 0);
  s.instance_boxes.clear();
  for (const Instance& instance : scene.instances) {
    const uint32_t end = uint32_t(std::min<size_t>(size_t(instance.first_triangle) + instance.triangle_count, scene.triangle_count()));
    const uint32_t first = std::min(instance.first_triangle, end);
    s.instance_boxes.push_back(triangles_world_box(scene, first, end - first));
    std::fill(instanced.begin() + first, instanced.begin() + end, uint8_t(1));
  }
  s.uninstanced_box = WorldBox{};
  for (uint32_t t = 0; t < uint32_t(scene.triangle_count()); ++t)
    if (!instanced[t]) s.uninstanced_box.grow(triangles_world_box(scene, t, 1));
}

}  // namespace

std::unique_ptr<RefreshSession> RefreshSession::open(const std::string& bundle_folder, const RefreshSessionOptions& options) {
  auto state = std::make_unique<State>();
  using Clock = std::chrono::steady_clock;
  Clock::time_point lap = Clock::now();
  auto since = [&lap] {
    const Clock::time_point now = Clock::now();
    const double seconds = std::chrono::duration<double>(now - lap).count();
    lap = now;
    return seconds;
  };
  OpenTimings& timings = state->open_timings;
  // The Vulkan device (instance, device chosen and made) on a thread of its own while the bundle is
  // read: it needs nothing of the scene. A bad bundle still fails as such (the device's own failure,
  // if any, is only seen when it is taken below); the future's destructor waits for it.
  std::future<std::shared_ptr<PreparedVulkanDevice>> device =
      std::async(std::launch::async, [&device_options = options.device] { return VulkanIntegrator::prepare_device(device_options); });
  const fs::path bundle(bundle_folder);
  state->bundle = bundle_folder;
  state->manifest = read_manifest(bundle);
  const formats::BundleManifest& manifest = state->manifest;
  const std::string manifest_path = (bundle / "manifest.json").string();
  if (!manifest.scene)
    throw BundleInputError(manifest_path + ": scene: missing (baked before scene.bin existed); re-bake instead");
  if (manifest.scene->file.empty())
    throw BundleInputError(manifest_path + ": scene: bake wrote no scene.bin (" + manifest.scene->skipped + "); re-bake instead");
  try {
    state->scene_file = formats::read_scene_file((bundle / manifest.scene->file).string());
    state->persisted = restore_scene(*state->scene_file);
    if (manifest.svo) state->svo = formats::read_svo_file((bundle / manifest.svo->file).string());
  } catch (const formats::FormatError& e) {
    throw BundleInputError(e.what());
  }
  timings.read = since();

  // Settings absent from an older manifest take bake's defaults (formats::BakeSettings).
  const formats::BakeSettings baked = manifest.settings.value_or(formats::BakeSettings{});
  IntegratorSettings& settings = state->settings;
  settings.spp = baked.spp;
  settings.seed = options.seed ? *options.seed : baked.seed;
  settings.max_bounces = baked.bounces;
  settings.russian_roulette_start = baked.russian_roulette_start;
  settings.safety_bounce_cap = baked.safety_bounce_cap;
  settings.sampler = baked.sampler == "independent" ? kSamplerIndependent : kSamplerSobol;
  settings.light_layers = options.light_layers;
  settings.light_subpaths = options.light_subpaths;
  settings.light_subpaths_per_sample = options.light_subpaths_per_sample;
  if (options.light_subpaths) check_light_subpaths_per_sample(options.light_subpaths_per_sample, "RefreshSessionOptions::light_subpaths_per_sample");
  // A bundle baked with directional layers is refreshed with them (the same estimator, path.h).
  if (baked.directional == "sh1") settings.directional = DirectionalMode::Sh1;
  check_denoise_radius(options.denoise_radius, settings, "RefreshSessionOptions::denoise_radius");  // before the integrator is made

  try {
    state->lighting = std::make_shared<LightingScene>(build_lighting_scene(scene_of(*state), to_bvh4(state->persisted.bvh)));
  } catch (const std::invalid_argument& e) {
    throw BundleInputError((bundle / manifest.scene->file).string() + ": " + e.what());
  }
  timings.lighting_scene = since();
  // The host's indices for edits are built on their own thread while the device is made: both only
  // read the scene and the lighting scene, and write disjoint state.
  std::future<void> indices = std::async(std::launch::async, [&s = *state] {
    s.texel_grid = TexelGrid(s.persisted.gbuffer);
    s.near_marks.assign(s.persisted.gbuffer.texels.size(), 0);
    index_for_edits(s);
    s.all_texels.resize(s.persisted.gbuffer.texels.size());
    for (size_t i = 0; i < s.all_texels.size(); ++i) s.all_texels[i] = uint32_t(i);
  });
  state->integrator = VulkanIntegrator::create(state->lighting, options.device, device.get());
  timings.device = since();
  state->priority_samples = options.priority_samples;
  state->proportional_split_samples = options.proportional_split_samples;
  indices.get();
  timings.indices = since();
  state->integrator->start_progressive(state->persisted.gbuffer, settings);
  state->denoise_radius = options.denoise_radius;
  if (options.refresh_probes && state->persisted.has_probe_grid() && manifest.probes) {
    if (!(options.probe_budget_share > 0 && options.probe_budget_share <= 1))
      throw std::invalid_argument("RefreshSessionOptions::probe_budget_share must be in (0, 1]");
    std::vector<Vec3> positions;
    const std::vector<formats::ProbeRecord>& probes = state->persisted.probes.probes;
    for (size_t i = 0; i < probes.size(); ++i)
      if (formats::probe_is_usable(probes[i])) {
        positions.push_back({probes[i].position[0], probes[i].position[1], probes[i].position[2]});
        state->probe_grid_index.push_back(i);
      }
    state->probe_target = std::max(1u, baked.probe_spp);
    state->probe_dering = baked.probe_dering_window;
    state->probe_budget_share = options.probe_budget_share;
    // What they show until refreshed: the bundle's probes.bin, as many samples as the bake gave
    // them (none when the bundle has lost it: then the refreshed estimate from its first set).
    state->previous_probes.assign(positions.size(), KeptProbe{});
    state->probe_switch_samples = 0;
    const fs::path probes_file = bundle / manifest.probes->file;
    if (fs::exists(probes_file)) {
      try {
        const formats::ProbeGrid baked_probes = formats::read_probes_file(probes_file.string());
        if (baked_probes.probes.size() != probes.size())
          throw BundleInputError(probes_file.string() + ": " + std::to_string(baked_probes.probes.size()) +
                                 " probes, but scene.bin's probe grid has " + std::to_string(probes.size()));
        for (size_t k = 0; k < positions.size(); ++k)
          state->previous_probes[k] = {baked_probes.probes[state->probe_grid_index[k]].sh, state->probe_target, -1.0};
        state->probe_switch_samples = state->probe_target;
      } catch (const formats::FormatError& e) {
        throw BundleInputError(e.what());
      }
    }
    // Kept per light layer as the texels are, so that an edit scaling lights scales them too.
    state->integrator->start_probe_refresh(positions, settings.light_layers ? int(state->lighting->light_layer_count) : 0);
  }
  timings.texels = since();
  if (options.start_from_baked) {
    try {
      // Shaped as the accumulation, with the bundle's light layers where it has them; without, they
      // stay 0 (no split: an edit that scales lights scales these texels as the accumulation's split says).
      BakedLightLayers layers;
      if (state->integrator->light_layers() > 0)
        layers = {uint32_t(state->integrator->light_layers()), state->lighting->punctual_light_layers};
      bool baked_layers = false;
      std::optional<LightmapEstimate> baked =
          read_baked_lightmap(bundle_folder, manifest, state->persisted.gbuffer,
                              std::clamp(settings.recorded_bounces, 1, int(kMaxRecordedLayers)), layers, &baked_layers);
      if (baked) {
        state->previous = state->integrator->upload_lightmap(*baked);
        state->previous_split_by_light = baked_layers;
      }
      state->started_from_baked = state->previous != nullptr;
    } catch (const std::runtime_error& e) {
      throw BundleInputError(e.what());
    }
  }
  timings.baked = since();
  // The publishing pipeline made (on lavapipe compiled) and a published estimate's device memory
  // allocated here, not in the first edit (which reuses it).
  state->integrator->publish(PublishMode::Accumulation, nullptr, nullptr);
  if (settings.light_layers) state->integrator->prepare_light_layer_scaling();  // not inside the first edit
  // A city block's move stages ~3.6 MB of geometry and its texels' start points: room for both.
  state->integrator->reserve_edit_staging(size_t(4) << 20);
  timings.publish = since();
  return std::unique_ptr<RefreshSession>(new RefreshSession(std::move(state)));
}

RefreshSession::RefreshSession(std::unique_ptr<State> state) : state_(std::move(state)) {}
RefreshSession::~RefreshSession() = default;

EditEffects RefreshSession::apply_edits(const std::vector<SceneEdit>& edits) {
  State& s = *state_;
  using Clock = std::chrono::steady_clock;
  auto since = [](Clock::time_point& t) {
    const Clock::time_point now = Clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - t).count();
    t = now;
    return ms;
  };
  Clock::time_point lap = Clock::now();
  EditTimings timings;
  const uint64_t submissions_before = s.integrator->waited_submissions();
  const double wait_before = s.integrator->wait_seconds();
  const std::vector<GpuPunctualLight> lights_before = s.lighting->punctual_lights;
  const std::optional<LightsBefore> layer_lights_before =
      s.settings.light_layers ? std::optional<LightsBefore>(exitance::lights_before(*s.lighting)) : std::nullopt;
  ChangeBefore was;
  for (const PunctualLight& light : s.persisted.scene.lights) was.light_positions.push_back(light.position);
  // Validated and computed on copies of the small parts, then committed in place (the session's
  // lighting scene reads persisted.scene itself); nothing below throws for bad input.
  InPlaceEdits in_place = apply_scene_edits_in_place(s.persisted, edits, &s.instance_texels, true);
  // The moved texels are rewritten on their own thread beside the lighting scene's refit below
  // (each reads the committed scene; they write the G-buffer's moved texels and the lighting scene).
  std::future<void> texels_moved;
  if (in_place.move_texels) texels_moved = std::async(std::launch::async, in_place.move_texels);
  const EditEffects& effects = in_place.effects;
  if (effects.geometry_changed() || !effects.materials.empty()) s.voxel_deposits_current = false;  // texels moved, or their albedo or emission
  // Edits of punctual lights alone upload the lights after the publish below, in the submission
  // that starts the accumulation again (start_progressive_change) or in one of their own.
  const bool punctual_only = !effects.geometry_changed() && effects.materials.empty() && !effects.sky && !effects.lights.empty();
  // Encoded again from the edited scene when a bundle is written; freed outside the edit.
  if (s.scene_file) s.stale_scene_file = std::move(s.scene_file);
  s.scene_file.reset();
  LightingScene& lighting = *s.lighting;
  std::vector<uint32_t> moved_bvh_nodes;  // geometry edits: uploaded below, beside the texels' host work
  bool moved_emitters = false;
  if (effects.geometry_changed()) {
    for (size_t j = 0; j < effects.moved_instances.size(); ++j) s.instance_boxes[effects.moved_instances[j]] = in_place.moved_boxes_after[j];
    WorldBox bounds = s.uninstanced_box;
    for (const WorldBox& b : s.instance_boxes) bounds.grow(b);
    const MovedTrianglesRefresh moved = refresh_moved_triangles_from_source(lighting, s.bvh_links, in_place.moved_triangles,
                                                                            in_place.moved_triangles_before, bounds);
    for (uint32_t n : moved.bvh_nodes) std::memcpy(&s.persisted.bvh.nodes[n], &lighting.bvh.nodes[n], sizeof(Bvh4Node));
    if (!effects.materials.empty()) refresh_materials_from_source(lighting, effects.materials);
    if (effects.sky) refresh_lights_from_source(lighting, {}, true);
    moved_bvh_nodes = moved.bvh_nodes;
    moved_emitters = moved.emitters_changed;
  } else {
    if (!effects.materials.empty()) {
      refresh_materials_from_source(lighting, effects.materials);
      s.integrator->update_materials(lighting);
    }
    if (!effects.lights.empty() || effects.sky) {
      refresh_lights_from_source(lighting, effects.lights, effects.sky);
      if (!punctual_only) s.integrator->update_lights(lighting);
    }
  }
  if (texels_moved.valid()) texels_moved.get();
  timings.scene = since(lap);
  // Edits that only scaled lights' emission: their layers scaled where the estimates are, 0 rays,
  // every sample kept (light_layer_edits.h).
  if (layer_lights_before) {
    const std::optional<std::vector<Vec4>> factors = light_layer_factors(*layer_lights_before, lighting, effects);
    if (factors && scale_light_layers(*factors, punctual_only)) {
      scale_probes(*factors);
      timings.restart = since(lap);
      timings.scaled_light_layers = true;
      timings.device_submissions = s.integrator->waited_submissions() - submissions_before;
      timings.device_wait = (s.integrator->wait_seconds() - wait_before) * 1e3;
      s.edit_timings = timings;
      return effects;
    }
  }
  // A geometry edit's upload (the refit nodes, the moved triangles' records, the emitters) runs on
  // its own thread while this one moves texels and starts the search for those near the change:
  // they read the lighting scene and write disjoint state, and nothing else here records device
  // work until it is joined (the texels' upload below). Its errors are the device's, rethrown there.
  std::future<void> geometry_upload;
  if (effects.geometry_changed())
    geometry_upload = std::async(std::launch::async, [&] {
      s.integrator->update_moved_geometry(lighting, s.bvh_links, in_place.moved_triangles, moved_bvh_nodes, moved_emitters,
                                          !effects.materials.empty());
      if (effects.sky) s.integrator->update_lights(lighting);
    });
  std::vector<uint32_t> changed_texels;
  if (effects.geometry_changed()) {
    // Moved texels leave their grid cells; the unocclude step again near the moved bounds (as a
    // fresh bake would place the texels); the start points of every texel that moved, uploaded.
    for (uint32_t i : in_place.moved_texels) s.texel_grid.displace(i, s.persisted.gbuffer.texels[i]);
    std::vector<WorldBox> boxes;
    for (size_t j = 0; j < effects.moved_instances.size(); ++j) {
      boxes.push_back(in_place.moved_boxes_before[j]);
      boxes.push_back(in_place.moved_boxes_after[j]);
    }
    const std::vector<uint32_t> carried =
        texels_carried_rigidly(s.persisted, in_place.moved_texels, effects.moved_instances, in_place.moved_deltas,
                               in_place.moved_boxes_before, s.instance_boxes, s.uninstanced_box, &lighting);
    const std::vector<uint32_t> unoccluded = unocclude_near_boxes(s.persisted, boxes, lighting, &s.texel_grid, &carried);
    for (uint32_t i : unoccluded) s.texel_grid.displace(i, s.persisted.gbuffer.texels[i]);
    std::set_union(in_place.moved_texels.begin(), in_place.moved_texels.end(), unoccluded.begin(), unoccluded.end(),
                   std::back_inserter(changed_texels));
  }
  timings.texels = since(lap);
  was.moved_boxes_before = in_place.moved_boxes_before;
  was.moved_boxes_after = in_place.moved_boxes_after;
  // The texels near the change are found on their own thread while this one records and waits for
  // the device work below (the moved geometry's and texels' uploads, the publish), which neither
  // reads nor writes what the search reads (the edited scene, the lighting scene, the texel grid,
  // the marks' scratch): host search and device waits overlap (a light edit's 0.7 ms search and
  // 0.5 ms publish were back to back). Joined before the grid is rebuilt or the list is used.
  std::future<std::vector<uint32_t>> near_search = std::async(std::launch::async, [&] {
    return texels_near_change(s.persisted, was, lighting, effects, &s.texel_grid, &s.near_marks);
  });
  if (geometry_upload.valid()) {
    geometry_upload.get();
    s.integrator->update_texels(s.persisted.gbuffer, changed_texels);
  }
  timings.uploads = since(lap);

  // Edits of punctual lights alone are estimated as a change from what was published before them
  // (path.h punctual_change_rays): the same paths, each vertex adding the edited lights' direct
  // light as edited minus as it was, so texels no edited light reaches keep their value exactly.
  const bool lights_only = punctual_only && !s.per_bounce && s.settings.directional == DirectionalMode::Off;
  std::vector<GpuPunctualLight> pairs;
  const std::vector<GpuPunctualLight>& base_lights = s.base ? s.base_lights : lights_before;
  const std::vector<GpuPunctualLight>& lights_now = s.lighting->punctual_lights;
  if (lights_only && base_lights.size() == lights_now.size())
    for (size_t i = 0; i < base_lights.size(); ++i)
      if (std::memcmp(&base_lights[i], &lights_now[i], sizeof(GpuPunctualLight)) != 0) {
        pairs.push_back(lights_now[i]);
        pairs.push_back(base_lights[i]);
      }
  // What is shown until refreshed again, kept on the device; the accumulation cleared in the same
  // submission (it starts again below) unless a whole run's result is published from the host.
  since(lap);
  const bool clears = !s.per_bounce;
  const bool split = published_split_by_light();
  const PublishedLightmap published = publish_on_device(clears, split);
  timings.publish = since(lap);
  std::vector<uint32_t> near = near_search.get();
  // Set-aside texels are visited by every query: past an eighth of them, the grid is built again.
  if (s.texel_grid.displaced_count() > s.persisted.gbuffer.texels.size() / 8) s.texel_grid = TexelGrid(s.persisted.gbuffer);
  timings.near_texels = since(lap);
  // A base needs variances: after opening without the baked lightmap and before any refresh, restart.
  const bool as_change = lights_only && !pairs.empty() && pairs.size() / 2 <= kMaxChangedLights &&
                         (s.base || (published.single_sample_texels == 0 && published.sampled_texels > 0));
  s.last_edit_near.clear();
  if (as_change && !s.base) {
    s.base = published.lightmap;
    s.base_lights = lights_before;
    s.base_split_by_light = split;
  }
  s.previous = published.lightmap;
  s.previous_split_by_light = split;
  const bool texels_as_before = true;  // moved texels' start points were uploaded above
  if (as_change) {
    s.clear_accumulation();
    // Each pair's change goes to its light's layer (pairs are formed in light order above).
    std::vector<uint32_t> pair_layers;
    for (size_t i = 0; i < base_lights.size() && s.settings.light_layers; ++i)
      if (std::memcmp(&base_lights[i], &lights_now[i], sizeof(GpuPunctualLight)) != 0)
        pair_layers.push_back(punctual_light_layer(uint32_t(i), s.lighting->punctual_light_layers));
    s.integrator->start_progressive_change(s.persisted.gbuffer, s.settings, *s.lighting, pairs, texels_as_before, clears,
                                           pair_layers);
    s.changed_lights = uint32_t(pairs.size() / 2);
  } else {
    if (punctual_only) s.integrator->update_punctual_lights(lighting);
    // A change estimate ends here: `published` is what it showed (restart() would publish it again).
    s.base.reset();
    s.base_lights.clear();
    s.changed_lights = 0;
    const bool same_texels = texels_as_before && !s.per_bounce;
    s.clear_accumulation();
    s.integrator->start_progressive(s.persisted.gbuffer, s.settings, same_texels, clears);
  }
  if (s.priority_samples > 0 && !near.empty() && near.size() < s.all_texels.size()) {
    s.near_texels = std::move(near);  // the far texels are listed when their turn comes (refresh)
    s.last_edit_near = s.near_texels;
  }
  {
    // Probes start again, those nearest a local change first (a light moved, an instance moved);
    // after a change everywhere (the sun, the sky, a material) in their own order. Where the
    // lightmap estimates the lights' change, the probes estimate it too, from what they showed.
    std::vector<Vec3> points;
    bool global = effects.sky || !effects.materials.empty();
    for (uint32_t i : effects.lights) {
      if (s.persisted.scene.lights[i].type == PunctualLight::Type::Directional) global = true;
      points.push_back(was.light_positions[i]);
      points.push_back(s.persisted.scene.lights[i].position);
    }
    std::vector<WorldBox> boxes = in_place.moved_boxes_before;
    boxes.insert(boxes.end(), in_place.moved_boxes_after.begin(), in_place.moved_boxes_after.end());
    restart_probes(global ? std::vector<Vec3>{} : points, global ? std::vector<WorldBox>{} : boxes, as_change);
  }
  timings.restart = since(lap);
  timings.device_submissions = s.integrator->waited_submissions() - submissions_before;
  timings.device_wait = (s.integrator->wait_seconds() - wait_before) * 1e3;
  s.edit_timings = timings;
  return effects;
}

void RefreshSession::restart_probes(const std::vector<Vec3>& near_points, const std::vector<WorldBox>& near_boxes, bool as_change) {
  State& s = *state_;
  if (s.probe_grid_index.empty()) return;
  // What each probe shows now is what it shows until its refreshed estimate of the edited scene is
  // the better by the publishing rule (or, where what it shows has no known variance, until that
  // estimate has one stratified set or the bake's probe_spp, if fewer).
  const uint32_t switch_samples = std::min(s.probe_target, kProbeStratifiedSetSize);
  if (s.integrator->probe_refresh_most_samples() > 0) {  // some probe may show its refreshed estimate
    std::vector<bool> refreshed_shown;
    std::vector<KeptProbe> records;
    published_probes(s.integrator->probe_refresh_estimate(), &refreshed_shown, &records);
    for (size_t k = 0; k < s.probe_grid_index.size(); ++k)
      if (refreshed_shown[k]) s.previous_probes[k] = records[k];
  }
  // A change estimate's base is what the probes showed at its first edit; later edits of it keep it.
  if (!as_change) s.probe_base.clear();
  else if (s.probe_base.empty()) s.probe_base = s.previous_probes;
  s.probe_switch_samples = switch_samples;
  s.previous_probes_uploaded = false;
  std::vector<Vec3> positions;
  if (!near_points.empty() || !near_boxes.empty())
    for (size_t i : s.probe_grid_index) {
      const formats::ProbeRecord& r = s.persisted.probes.probes[i];
      positions.push_back({r.position[0], r.position[1], r.position[2]});
    }
  size_t near = 0;
  const std::vector<uint32_t> order = probes_nearest_first(positions, near_points, near_boxes, 0.1f * s.lighting->extent, &near);
  s.integrator->clear_probe_refresh(order, near, as_change);
}

void RefreshSession::scale_probes(const std::vector<Vec4>& factors) {
  State& s = *state_;
  if (s.probe_grid_index.empty()) return;
  if (s.integrator->probe_refresh_light_layers() != int(factors.size())) return restart_probes();
  // What probes showed before the last edit, scaled by their refreshed estimate's split (a read-back
  // of each scaled layer), then the refreshed sums themselves on the device: every sample kept.
  if (s.integrator->probe_refresh_most_samples() > 0)
    for (size_t l = 0; l < factors.size(); ++l)
      if (factors[l].w != 0)
        scale_kept_probes(s.previous_probes, s.integrator->probe_refresh_layer(int(l)), Vec4(factors[l].x, factors[l].y, factors[l].z, 0),
                          s.probe_dering);
  s.integrator->scale_probe_layers(factors);
  s.previous_probes_uploaded = false;
}

const DeviceProbeBuffer& RefreshSession::publish_probe_buffer() {
  State& s = *state_;
  if (s.probe_grid_index.empty())
    throw std::invalid_argument("the session refreshes no light probes (the bundle has none, or refresh_probes is off)");
  std::vector<uint32_t> grid_index(s.probe_grid_index.begin(), s.probe_grid_index.end());
  std::vector<double> kept;
  if (!s.previous_probes_uploaded) {
    kept.reserve(s.previous_probes.size() * 57);  // ProbePublisher::kKeptWords
    for (size_t k = 0; k < s.previous_probes.size(); ++k) {
      const KeptProbe& previous = s.previous_probes[k];
      for (float v : previous.sh) kept.push_back(v);
      kept.push_back(previous.samples);
      kept.push_back(previous.variance);
      const KeptProbe base = s.probe_base.empty() ? KeptProbe{} : s.probe_base[k];
      for (float v : base.sh) kept.push_back(v);
      kept.push_back(base.samples);
    }
  }
  // The dering window per band, as store_probe_radiance applies it (none: 1).
  const std::array<float, 3> band_weight = probe_band_weights(s.probe_dering);
  const DeviceProbeBuffer& buffer =
      s.integrator->write_probe_buffer(s.persisted.probes.probes.size(), grid_index, s.previous_probes_uploaded ? nullptr : &kept,
                                       std::max(1u, s.probe_switch_samples), band_weight);
  s.previous_probes_uploaded = true;
  return buffer;
}

std::vector<float> RefreshSession::read_probe_buffer() const { return state_->integrator->read_probe_buffer(); }

const DeviceVoxelExitance& RefreshSession::publish_voxel_exitance() {
  State& s = *state_;
  if (!s.svo) throw std::invalid_argument("the bundle has no svo.bin (baked with --voxel-resolution none)");
  std::optional<VoxelDeposits> deposits;
  if (!s.voxel_deposits_current) deposits = voxel_deposits(*s.svo, s.persisted.scene, s.persisted.gbuffer);
  const DeviceVoxelExitance& out = s.integrator->write_voxel_exitance(*shown_on_device(nullptr, true), *s.svo, deposits ? &*deposits : nullptr);
  s.voxel_deposits_current = true;
  return out;
}

std::vector<float> RefreshSession::read_voxel_exitance() const { return state_->integrator->read_voxel_exitance(); }

formats::ProbeGrid RefreshSession::published_probes() const {
  const State& s = *state_;
  if (s.probe_grid_index.empty()) return {};
  if (s.integrator->probe_refresh_most_samples() == 0) return published_probes(ProbeEstimate{}, nullptr);
  return published_probes(s.integrator->probe_refresh_estimate(), nullptr);
}

formats::ProbeGrid RefreshSession::published_probes(const ProbeEstimate& refreshed, std::vector<bool>* refreshed_shown,
                                                    std::vector<KeptProbe>* records) const {
  const State& s = *state_;
  formats::ProbeGrid grid = s.persisted.probes;
  const size_t count = s.probe_grid_index.size();
  if (refreshed_shown) refreshed_shown->assign(count, false);
  if (records) *records = s.previous_probes;
  for (size_t k = 0; k < count; ++k) grid.probes[s.probe_grid_index[k]].sh = s.previous_probes[k].sh;
  if (refreshed.samples.size() != count) return grid;  // none refreshed
  if (!s.probe_base.empty()) {
    // A change estimate: the base, or the base plus the change where it is significant.
    const std::array<float, 3> band_weight = probe_band_weights(s.probe_dering);
    for (size_t k = 0; k < count; ++k) {
      const uint32_t choice = probe_change_choice(s.probe_base[k], refreshed, k);
      if (choice == kPublishPrevious) continue;
      const KeptProbe shown =
          choice == kPublishBase ? s.probe_base[k] : probe_base_plus_change(s.probe_base[k], refreshed, k, band_weight);
      grid.probes[s.probe_grid_index[k]].sh = shown.sh;
      if (refreshed_shown) (*refreshed_shown)[k] = true;
      if (records) (*records)[k] = shown;
    }
    return grid;
  }
  // The probes whose refreshed estimate the publishing rule prefers, as probes.bin stores them.
  std::vector<size_t> shown;
  std::vector<size_t> shown_k;
  ProbeEstimate subset;
  for (size_t k = 0; k < count; ++k) {
    if (!probe_shows_refreshed(s.previous_probes[k], refreshed, k, std::max(1u, s.probe_switch_samples))) continue;
    if (refreshed_shown) (*refreshed_shown)[k] = true;
    shown.push_back(s.probe_grid_index[k]);
    shown_k.push_back(k);
    subset.sh_sum.push_back(refreshed.sh_sum[k]);
    subset.samples.push_back(refreshed.samples[k]);
    subset.backface_hits.push_back(refreshed.backface_hits[k]);
  }
  store_probe_radiance(grid, shown, subset, s.probe_dering);
  if (records)
    for (size_t j = 0; j < shown.size(); ++j) {
      const size_t k = shown_k[j];
      (*records)[k] = {grid.probes[shown[j]].sh, refreshed.samples[k], refreshed.l0_variance_of_mean(k)};
    }
  return grid;
}

std::optional<formats::SparseVoxelOctree> RefreshSession::published_voxel_exitance() const {
  const State& s = *state_;
  if (!s.svo) return std::nullopt;
  formats::SparseVoxelOctree svo = *s.svo;
  fill_svo_exitance(svo, s.persisted.scene, s.persisted.gbuffer, shown_lightmap());
  return svo;
}

void RefreshSession::set_denoise_radius(int radius) {
  check_denoise_radius(radius, state_->settings, "set_denoise_radius");
  state_->denoise_radius = radius;
}

int RefreshSession::denoise_radius() const { return state_->denoise_radius; }

std::shared_ptr<DeviceLightmap> RefreshSession::shown_on_device(DeviceDenoiseCounts* counts, bool totals_only) const {
  const State& s = *state_;
  const PublishedLightmap published = publish_on_device();
  if (s.denoise_radius == 0) return published.lightmap;
  return s.integrator->denoise_indirect(*published.lightmap, s.persisted.gbuffer, s.denoise_radius, counts, totals_only);
}

LightmapEstimate RefreshSession::shown_lightmap(DeviceDenoiseCounts* counts) const {
  if (state_->denoise_radius == 0) return published_lightmap();
  return state_->integrator->read_lightmap(*shown_on_device(counts));
}

void RefreshSession::set_probe_budget_share(double share) {
  if (!(share >= 0 && share <= 1))
    throw std::invalid_argument("probe budget share " + std::to_string(share) + " is not in [0, 1]");
  state_->probe_budget_share = share;
}

void RefreshSession::set_light_subpaths(bool on, double per_sample) {
  check_light_subpaths_per_sample(per_sample, "set_light_subpaths");
  IntegratorSettings settings = state_->settings;
  settings.light_subpaths = on;
  settings.light_subpaths_per_sample = per_sample;
  // The probes' sets read the session's settings as each is traced; the texels' passes take them here.
  state_->integrator->set_progressive_light_subpaths(settings);
  state_->settings = settings;
}

bool RefreshSession::refreshes_probes() const { return !state_->probe_grid_index.empty(); }

RefreshSession::ProbeErrors RefreshSession::probe_errors() const {
  const State& s = *state_;
  ProbeErrors errors;
  errors.probes = uint32_t(s.probe_grid_index.size());
  if (s.probe_grid_index.empty()) return errors;
  const ProbeEstimate refreshed = s.integrator->probe_refresh_most_samples() > 0 ? s.integrator->probe_refresh_estimate() : ProbeEstimate{};
  std::vector<bool> refreshed_shown;
  std::vector<KeptProbe> records;
  const formats::ProbeGrid shown = published_probes(refreshed, &refreshed_shown, &records);
  double sum = 0;
  for (size_t k = 0; k < s.probe_grid_index.size(); ++k) {
    const bool fresh = refreshed_shown[k];
    errors.showing_refreshed += fresh;
    const double variance = records[k].variance;
    if (variance < 0 || (fresh && refreshed.samples[k] < 2)) continue;
    double signal = 0;
    const std::array<float, 27>& sh = shown.probes[s.probe_grid_index[k]].sh;
    for (size_t c = 0; c < 3; ++c) signal += double(sh[c]) * sh[c];
    sum += variance / (std::max(0.0, signal - variance) + 1e-3);
    ++errors.with_variance;
  }
  errors.estimated_relative_mse = errors.with_variance > 0 ? sum / errors.with_variance : NAN;
  return errors;
}

uint32_t RefreshSession::probe_samples() const {
  return state_->probe_grid_index.empty() ? 0 : state_->integrator->probe_refresh_samples();
}

void RefreshSession::end_change_estimate() {
  State& s = *state_;
  if (!s.base) return;
  // The probes' change estimate ends with it: what they show, kept; their sums start again.
  if (!s.probe_base.empty()) restart_probes();
  // What the change estimate published is what texels show until refreshed again.
  const bool split = published_split_by_light();
  s.previous = publish_on_device(false, split).lightmap;
  s.previous_split_by_light = split;
  s.base.reset();
  s.base_lights.clear();
  s.changed_lights = 0;
}

bool RefreshSession::published_split_by_light() const {
  const State& s = *state_;
  // A change estimate's changes are split by light (GpuParams::changed_light_layers): base + change
  // is split where base and what was shown are.
  if (s.base) return s.integrator->light_layers() > 0 && s.base_split_by_light && s.previous_split_by_light;
  if (s.per_bounce) {  // a whole run, shown wherever it has samples, previous elsewhere
    if (!s.whole_run_path || s.per_bounce->light_layers == 0) return false;
    if (!s.previous || s.previous_split_by_light) return true;
    for (const TexelAccumulator& t : s.per_bounce->texels)
      if (t.samples == 0) return false;
    return true;
  }
  return s.integrator->light_layers() > 0 && (!s.previous || s.previous_split_by_light);
}

bool RefreshSession::scale_light_layers(const std::vector<Vec4>& factors, bool punctual_only) {
  State& s = *state_;
  // During a change estimate, an edited light's change is estimated against its record at the base,
  // which a scaled layer would not match: such edits stay pairs of the change estimate. A per-bounce
  // run keeps no light layers.
  if (s.base) return false;
  if (s.per_bounce && (!s.whole_run_path || s.per_bounce->light_layers != int(factors.size()))) return false;
  if (!s.per_bounce && s.integrator->light_layers() != int(factors.size())) return false;
  // Without a split of its own, what was shown is scaled by the accumulation's, which must have
  // samples enough (after a whole run the accumulation starts again: none).
  if (s.per_bounce && !published_split_by_light()) return false;
  if (!s.per_bounce && s.previous && !s.previous_split_by_light && samples_per_texel() < s.proportional_split_samples) return false;
  // Edits of punctual lights alone left their upload to the accumulation's restart (apply_edits).
  if (punctual_only) s.integrator->update_punctual_lights(*s.lighting);
  if (s.per_bounce) {
    // A whole run's result (on the host) becomes what is shown, scaled below; the accumulation
    // starts again behind it (its texel buffers were the run's).
    s.previous = publish_on_device().lightmap;
    s.previous_split_by_light = true;
    s.clear_accumulation();
    s.integrator->start_progressive(s.persisted.gbuffer, s.settings, false);
  }
  s.integrator->scale_light_layers(factors, s.previous.get(), s.previous_split_by_light);
  s.last_edit_near.clear();
  return true;
}

void RefreshSession::restart() { restart(false); }

void RefreshSession::restart(bool texels_as_before) {
  State& s = *state_;
  end_change_estimate();
  // After a whole run the texel buffers were its own: upload the texels again.
  const bool same_texels = texels_as_before && !s.per_bounce;
  s.clear_accumulation();
  s.integrator->start_progressive(s.persisted.gbuffer, s.settings, same_texels);
}

const EditTimings& RefreshSession::last_edit_timings() const { return state_->edit_timings; }
const OpenTimings& RefreshSession::open_timings() const { return state_->open_timings; }

const std::vector<uint32_t>& RefreshSession::texels_near_last_edit() const { return state_->last_edit_near; }

uint32_t RefreshSession::samples_per_texel() const {
  const State& s = *state_;
  if (s.per_bounce) return s.per_bounce->texels.empty() ? 0 : s.per_bounce->texels.front().samples;
  if (!s.near_texels.empty()) return s.far_samples;  // the far texels lag
  return s.all_samples;
}

// The fewest texels a pass over part of a list takes (refresh(), below): smaller ones are mostly
// their fixed cost.
constexpr size_t kLeastPartTexels = 4096;
// Budgets above this (ms) are spent in passes of at most half of what is left (refresh(), below).
constexpr double kHalvingAboveMs = 50;

RefreshReport RefreshSession::refresh(const RefreshBudget& budget) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  if (!(budget.milliseconds >= 0) || !std::isfinite(budget.milliseconds))
    throw std::invalid_argument("RefreshSession::refresh: budget milliseconds must be finite and not negative");
  if (budget.milliseconds == 0 && budget.max_samples_per_texel == 0 && budget.texel_samples == 0)
    throw std::invalid_argument("RefreshSession::refresh: a budget needs milliseconds, a sample cap or texel-samples");
  State& s = *state_;
  s.stale_scene_file.reset();  // inside the frame's time, not the edit's
  if (s.per_bounce) restart();  // the progressive accumulation again, from sample 0
  VulkanIntegrator& integrator = *s.integrator;
  const uint32_t cap = budget.max_samples_per_texel ? budget.max_samples_per_texel : std::numeric_limits<uint32_t>::max();
  RefreshReport report;
  auto elapsed_ms = [&] { return std::chrono::duration<double, std::milli>(Clock::now() - start).count(); };
  // Probes first (a frame's budget: the lightmap's passes are sized from what is left): a stratified
  // set for as many of the next probes as fit their share of the budget, by the measured cost.
  if (budget.milliseconds > 0 && s.probe_budget_share > 0 && !s.probe_grid_index.empty() &&
      integrator.probe_refresh_samples() < s.probe_target) {
    const double share = s.probe_budget_share * budget.milliseconds;
    // The batch is scaled by share / the last batch's time (a batch costs a fixed part, its pass,
    // plus a part per probe: this converges on the batch whose time is the share), rounded up so
    // that it can grow from one probe, and by at most 2x either way a call, so that one slow batch
    // (a first dispatch that compiled its pipeline) costs a few calls, not the session. Unmeasured:
    // 16 probes; at least one probe a call, so probes always progress.
    size_t fitting = 16;
    if (s.probe_last_batch > 0 && s.probe_last_batch_ms > 0) {
      const double scaled = std::ceil(double(s.probe_last_batch) * share / s.probe_last_batch_ms);
      fitting = size_t(std::clamp(scaled, std::max(1.0, std::floor(s.probe_last_batch / 2.0)), 2.0 * double(s.probe_last_batch)));
    }
    const auto probes_start = Clock::now();
    size_t refreshed = 0;
    report.probe_rays = integrator.refresh_probe_set(s.settings, s.probe_target, fitting, &refreshed);
    report.probes_refreshed = uint32_t(refreshed);
    const double ms = std::chrono::duration<double, std::milli>(Clock::now() - probes_start).count();
    if (refreshed > 0) s.probe_last_batch = refreshed, s.probe_last_batch_ms = ms;
  }
  report.probe_samples = s.probe_grid_index.empty() ? 0 : integrator.probe_refresh_samples();
  const uint32_t samples_before = samples_per_texel();
  uint64_t used = 0;  // texel-samples
  for (;;) {
    // Which texels the next pass takes, from which sample index, and how many samples at most.
    const std::vector<uint32_t>* list = &s.all_texels;
    uint32_t* count = &s.all_samples;
    uint32_t limit = cap;
    if (!s.near_texels.empty()) {
      if (s.near_samples < std::min(cap, s.priority_samples)) {
        list = &s.near_texels, count = &s.near_samples, limit = std::min(cap, s.priority_samples);
      } else if (s.far_samples < s.near_samples) {
        if (s.far_texels.empty()) {  // every texel not near (near_texels ascends), listed at its first turn
          s.far_texels.reserve(s.all_texels.size() - s.near_texels.size());
          size_t k = 0;
          for (uint32_t i = 0; i < uint32_t(s.all_texels.size()); ++i) {
            if (k < s.near_texels.size() && s.near_texels[k] == i) {
              ++k;
              continue;
            }
            s.far_texels.push_back(i);
          }
        }
        list = &s.far_texels, count = &s.far_samples, limit = s.near_samples;
      } else {  // caught up: one list again, at their common count
        s.all_samples = s.near_samples;
        s.near_texels.clear();
        s.far_texels.clear();
        continue;
      }
    }
    if (*count >= limit) break;
    uint32_t pass = limit - *count;
    // A pass is `pass` whole samples of the list or, with `part` > 0, one sample of its texels
    // [s.partial, s.partial + part): when less than one sample of the list fits the budget, or one
    // is under way (each texel still takes its samples in order, as in a bake; a list is left only
    // once its sample is complete).
    size_t part = s.partial > 0 ? list->size() - s.partial : 0;
    if (budget.texel_samples > 0) {
      const uint64_t left = budget.texel_samples - std::min(budget.texel_samples, used);
      if (left == 0) break;
      if (part > 0) part = size_t(std::min<uint64_t>(part, left));
      else if (left < list->size()) part = size_t(left);
      else pass = uint32_t(std::min<uint64_t>(pass, left / list->size()));
    }
    if (budget.milliseconds > 0) {
      // Passes sized from the measured pass cost, so the call ends near its budget; the first
      // pass of a session is one sample, to measure it. Before the fit exists, one pass is one
      // sample larger than the conservative estimate allows, once, to measure a second size.
      const double remaining = budget.milliseconds - elapsed_ms();
      if (remaining <= 0) break;
      if (s.pass_cost.texels != list->size()) {
        // A list not measured yet (the texels near an edit, then the others) is sized from the
        // last list's cost and starts within the call (before, a call ended at a list switch and
        // left its budget unused, and the list's first pass was one sample); with nothing
        // measured at all, one sample, only at the start of a call, where the whole budget is left.
        if (!(s.pass_cost.ms_per_work > 0) && report.rays > 0) break;
        s.pass_cost = s.pass_cost.for_list(list->size());
      }
      double fitting = s.pass_cost.fitting(remaining, list->size());
      // A long budget (a whole relight under --time) is not spent in one pass sized by a model fitted
      // on 1- and 2-sample passes (measured: 24 % over a 1 s budget on an H200): while more than
      // kHalvingAboveMs is left a pass takes at most half of it, so the model is refitted on passes
      // nearer the final size and only the last, short pass relies on it.
      if (remaining > kHalvingAboveMs && fitting >= 2)
        fitting = std::max(1.0, std::min(fitting, s.pass_cost.fitting(0.5 * remaining, list->size())));
      if (part == 0 && !s.pass_cost.fitted && !s.pass_cost.explored && s.pass_cost.last_work > 0 && fitting >= 1 &&
          remaining >= 1.25 * s.pass_cost.last_ms) {
        fitting += 1;
        s.pass_cost.explored = true;
      }
      if (part > 0 || (fitting < 1 && s.pass_cost.ms_per_work > 0)) {
        // One sample of as many of the list's texels as fit (a frame shorter than one sample of
        // the lightmap: lavapipe, or a budget of a millisecond or two on a GPU), at least
        // kLeastPartTexels, and that only as a call's first pass (a call adds at least one).
        if (part == 0) part = list->size();
        const double fit = s.pass_cost.fitting_texels(remaining);
        const size_t least = std::min(part, kLeastPartTexels);
        if (fit < double(least)) {
          if (report.rays > 0) break;
          part = least;
        } else if (fit < double(part)) {
          part = size_t(fit);
        }
      } else {
        pass = uint32_t(std::clamp(fitting, 1.0, double(pass)));
      }
    }
    const auto pass_start = Clock::now();
    double work = 0;
    if (part > 0) {
      const std::vector<uint32_t> texels(list->begin() + std::ptrdiff_t(s.partial), list->begin() + std::ptrdiff_t(s.partial + part));
      report.rays += integrator.add_samples_to(texels, *count, 1);
      s.partial += part;
      if (s.partial == list->size()) s.partial = 0, ++*count;
      work = double(part);
    } else {
      report.rays += integrator.add_samples_to(*list, *count, pass);
      *count += pass;
      work = double(pass) * double(list->size());
    }
    used += uint64_t(work);
    if (list == &s.near_texels) report.prioritized_texels = uint32_t(list->size());
    s.pass_cost.add(work, std::chrono::duration<double, std::milli>(Clock::now() - pass_start).count());
    if (budget.milliseconds > 0 && elapsed_ms() >= budget.milliseconds) break;
  }
  report.samples_per_texel = samples_per_texel();
  report.samples_added = report.samples_per_texel - samples_before;
  report.capped = s.near_texels.empty() && s.all_samples >= cap;
  report.milliseconds = elapsed_ms();
  return report;
}

LightmapEstimate RefreshSession::lightmap() const {
  return state_->per_bounce ? *state_->per_bounce : state_->integrator->progressive_estimate();
}

const LightmapEstimate& RefreshSession::bake_per_bounce(uint32_t spp, double time_budget_seconds, bool caches_on_host) {
  State& s = *state_;
  end_change_estimate();
  if (s.settings.directional != DirectionalMode::Off)
    throw std::invalid_argument("the per-bounce mode estimates no directional (sh1) layers: relight this bundle with path tracing");
  if (spp == 0 && !(time_budget_seconds > 0))
    throw std::invalid_argument("the per-bounce mode needs samples per texel or a time budget");
  IntegratorSettings settings = s.settings;
  settings.integrator = IntegratorMode::Bounces;
  settings.light_subpaths = false;  // the per-bounce mode has no light-subpath strategy
  settings.spp = spp;
  settings.time_budget_seconds = time_budget_seconds;
  const formats::BakeSettings baked = s.manifest.settings.value_or(formats::BakeSettings{});
  settings.trace_first_bounce = baked.first_bounce != "cached";
  settings.bounce_caches_on_host = caches_on_host;
  budget_from_now(settings);
  s.per_bounce = s.integrator->bake(s.persisted.gbuffer, settings);
  s.whole_run_path = s.whole_run_guided = false;
  return *s.per_bounce;
}

bool RefreshSession::per_bounce() const { return state_->per_bounce.has_value() && !state_->whole_run_path; }

const LightmapEstimate& RefreshSession::bake_guided(uint32_t spp, double time_budget_seconds, float guiding_mix, GuidingMode mode) {
  State& s = *state_;
  end_change_estimate();
  if (spp == 0 && !(time_budget_seconds > 0))
    throw std::invalid_argument("guided path tracing needs samples per texel or a time budget");
  if (mode != GuidingMode::Grid && mode != GuidingMode::Svo && mode != GuidingMode::Auto)
    throw std::invalid_argument("bake_guided: the mode must be grid, svo or auto");
  IntegratorSettings settings = s.settings;
  settings.integrator = IntegratorMode::Path;
  settings.guiding = mode;
  // Auto: the scene's candidate (light subpaths in bakes long enough for their pilot, else grid
  // guiding: lightmap_driver.cpp), as bake --backend vulkan --guiding auto measures it.
  if (mode == GuidingMode::Auto) settings.guiding_auto_candidate = AutoGuidingCandidate::Scene;
  settings.light_subpaths = false;  // guiding is not combined with light subpaths
  if (mode == GuidingMode::Svo) {
    // The bundle's octree: its published exitance (the bake's light) seeds the guide's first fields.
    if (!s.svo) throw std::invalid_argument("--guiding svo: the bundle has no svo.bin (baked with --voxel-resolution none)");
    settings.guiding_octree = &*s.svo;
  }
  settings.guiding_mix = guiding_mix;
  settings.spp = spp;
  settings.time_budget_seconds = time_budget_seconds;
  budget_from_now(settings);
  s.per_bounce = s.integrator->bake(s.persisted.gbuffer, settings);
  s.whole_run_path = s.whole_run_guided = true;
  return *s.per_bounce;
}

const LightmapEstimate& RefreshSession::bake_path(uint32_t spp, double time_budget_seconds, WorkShare* share,
                                                  bool emitter_guiding, bool light_subpaths) {
  State& s = *state_;
  end_change_estimate();
  if (spp == 0 && !(time_budget_seconds > 0)) throw std::invalid_argument("path tracing in one run needs samples per texel or a time budget");
  IntegratorSettings settings = s.settings;
  settings.integrator = IntegratorMode::Path;
  settings.guiding = GuidingMode::Off;
  settings.spp = spp;
  settings.time_budget_seconds = time_budget_seconds;
  settings.work_share = share;
  settings.emitter_guiding = emitter_guiding;
  settings.light_subpaths = light_subpaths;
  budget_from_now(settings);
  s.per_bounce = s.integrator->bake(s.persisted.gbuffer, settings);
  s.whole_run_path = true;
  s.whole_run_guided = false;
  return *s.per_bounce;
}

bool RefreshSession::guided() const { return state_->per_bounce.has_value() && state_->whole_run_guided; }

LightmapEstimate RefreshSession::refreshed_lightmap() const {
  const State& s = *state_;
  return s.base ? add_change(s.integrator->read_lightmap(*s.base), lightmap()) : lightmap();
}

uint32_t RefreshSession::changed_lights() const { return state_->changed_lights; }
bool RefreshSession::started_from_baked() const { return state_->started_from_baked; }

PublishedLightmap RefreshSession::publish_on_device(bool clear_accumulation, bool light_layers) const {
  const State& s = *state_;
  if (s.per_bounce) {  // a whole run's result is on the host
    const LightmapEstimate estimate = published_lightmap();
    PublishedLightmap published;
    for (const TexelAccumulator& t : estimate.texels) {
      published.single_sample_texels += t.samples == 1;
      published.sampled_texels += t.samples >= 2;
    }
    published.lightmap = s.integrator->upload_lightmap(estimate);
    return published;
  }
  if (s.base)
    return s.integrator->publish(PublishMode::Change, s.previous ? s.previous.get() : s.base.get(), s.base.get(), clear_accumulation,
                                 light_layers);
  return s.integrator->publish(s.previous ? PublishMode::Restart : PublishMode::Accumulation, s.previous.get(), nullptr, clear_accumulation,
                               light_layers);
}

LightmapEstimate RefreshSession::published_lightmap() const {
  const State& s = *state_;
  if (!s.per_bounce) {
    const bool split = published_split_by_light();
    LightmapEstimate published = s.integrator->read_lightmap(*publish_on_device(false, split).lightmap);
    if (!split) std::fill(published.light_sums.begin(), published.light_sums.end(), 0.0);  // not composed: no split by light
    return published;
  }
  LightmapEstimate estimate = *s.per_bounce;
  if (!s.previous) return estimate;
  const LightmapEstimate previous = s.integrator->read_lightmap(*s.previous);
  if (previous.texels.size() != estimate.texels.size() || previous.recorded_bounces != estimate.recorded_bounces ||
      previous.has_sh1() != estimate.has_sh1() || previous.light_layers != estimate.light_layers)
    return estimate;
  // A whole run (bake_per_bounce, bake_guided, bake_path) is a bake: shown wherever it has samples.
  const size_t n = estimate.texels.size();
  for (size_t i = 0; i < n; ++i) {
    if (estimate.texels[i].samples > 0) continue;
    estimate.texels[i] = previous.texels[i];
    for (int k = 0; k < estimate.recorded_bounces; ++k)
      for (int c = 0; c < 3; ++c) estimate.bounces[(size_t(k) * n + i) * 3 + size_t(c)] = previous.bounces[(size_t(k) * n + i) * 3 + size_t(c)];
    for (int k = 0; k < estimate.light_layers; ++k)
      for (int c = 0; c < 3; ++c) estimate.light_sums[(size_t(k) * n + i) * 3 + size_t(c)] = previous.light_sums[(size_t(k) * n + i) * 3 + size_t(c)];
  }
  return estimate;
}

std::optional<LightmapEstimate> RefreshSession::published_lightmap_by_light() const {
  const State& s = *state_;
  const bool layers = s.per_bounce ? s.per_bounce->light_layers > 0 : s.integrator->light_layers() > 0;
  if (!layers) return std::nullopt;
  if (published_split_by_light()) return published_lightmap();
  // Only the progressive accumulation, not during a change estimate, with samples enough to split by.
  if (s.per_bounce || s.base || samples_per_texel() < s.proportional_split_samples) return std::nullopt;
  LightmapEstimate published = published_lightmap();
  const LightmapEstimate accumulation = lightmap();
  const size_t n = published.texels.size();
  if (accumulation.texels.size() != n || accumulation.light_layers != published.light_layers) return std::nullopt;
  const int layer_count = published.light_layers;
  for (size_t i = 0; i < n; ++i) {
    const TexelAccumulator& shown = published.texels[i];
    const TexelAccumulator& acc = accumulation.texels[i];
    for (int c = 0; c < 3; ++c) {
      // The shown total's sums split as the accumulation's mean is split (same samples or not).
      const double total = acc.total[c];
      for (int k = 0; k < layer_count; ++k) {
        const double part = total != 0 ? accumulation.light_sums[(size_t(k) * n + i) * 3 + size_t(c)] / total : (k == 0 ? 1.0 : 0.0);
        published.light_sums[(size_t(k) * n + i) * 3 + size_t(c)] = shown.total[c] * part;
      }
    }
  }
  return published;
}

const DevicePageImages& RefreshSession::publish_page_images(int dilation_texels) {
  State& s = *state_;
  return s.integrator->write_page_images(*shown_on_device(nullptr, true), s.persisted.gbuffer, dilation_texels);
}

int RefreshSession::page_dilation_texels() const {
  const formats::BakeSettings baked = state_->manifest.settings.value_or(formats::BakeSettings{});
  return std::max(2, int(baked.padding) * 2);
}

std::vector<float> RefreshSession::read_page_image(size_t page) const { return state_->integrator->read_page_image(page); }

double RefreshSession::estimated_relative_mse(const LightmapEstimate& estimate) {
  double sum = 0;
  size_t count = 0;
  for (size_t i = 0; i < estimate.texels.size(); ++i) {
    if (estimate.texels[i].samples < 2) continue;  // no variance estimate yet
    const Vec3 mean = estimate.mean_total(i), variance = estimate.variance_of_mean(i);
    // mean^2 overestimates the converged value's square by the variance of the mean (E[m^2] = r^2 + v).
    for (int c = 0; c < 3; ++c)
      sum += double(variance[c]) / (std::max(0.0, double(mean[c]) * mean[c] - variance[c]) + 1e-3);
    count += 3;
  }
  return count ? sum / double(count) : std::numeric_limits<double>::infinity();
}

ProbeEstimate RefreshSession::probe_estimate(uint32_t spp) {
  std::vector<Vec3> positions;
  for (const formats::ProbeRecord& r : state_->persisted.probes.probes)
    if (formats::probe_is_usable(r)) positions.push_back({r.position[0], r.position[1], r.position[2]});
  IntegratorSettings settings = state_->settings;
  settings.spp = spp;
  return state_->integrator->bake_probes(positions, settings);
}

const std::string& RefreshSession::bundle() const { return state_->bundle; }
const formats::BundleManifest& RefreshSession::manifest() const { return state_->manifest; }
const formats::SceneFile& RefreshSession::scene_file() const {
  const State& s = *state_;
  if (!s.scene_file)
    s.scene_file = make_scene_file(s.persisted.scene, s.persisted.gbuffer, s.persisted.atlas,
                                   s.persisted.has_probe_grid() ? &s.persisted.probes : nullptr, s.persisted.bvh);
  return *s.scene_file;
}
const PersistedScene& RefreshSession::persisted() const { return state_->persisted; }
const LightingScene& RefreshSession::lighting_scene() const { return *state_->lighting; }
const formats::SparseVoxelOctree* RefreshSession::svo() const { return state_->svo ? &*state_->svo : nullptr; }
const IntegratorSettings& RefreshSession::settings() const { return state_->settings; }
VulkanIntegrator& RefreshSession::integrator() { return *state_->integrator; }

}  // namespace exitance
