// The runtime's resident lighting state (DESIGN §3): a baked bundle opened from its manifest and
// scene.bin onto a Vulkan device (the library's own or one an engine hands over), its lightmap
// accumulated progressively on the device between calls, refreshed within a budget per call.
//
// refresh() adds samples to every live texel, continuing the sample indices of the calls before:
// after N samples in any number of calls the lightmap equals bake --backend vulkan's N samples
// with the same seed (lightmap(); published_lightmap() also weighs the baked or pre-edit value).
// restart() drops every accumulated sample (lightmap() keeps no value from before it); apply_edits
// restarts, except after edits that only scale lights, which scale their light layers with 0 rays
// and keep every sample, and after other edits of punctual lights alone, which it estimates as a
// change from what was shown (apply_edits below; docs/runtime.md "Light layers"). After a local edit (a moved instance, a point or spot light, an
// emissive material) the texels near it are refreshed first (priority_samples), then the others
// until they catch up; each texel's samples are still a bake's samples 0..N-1. What a texel shows
// (published_lightmap) is its value from before the edit (at open: the bundle's baked lightmap)
// until the refreshed estimate has the lower estimated error (refresh/published_estimate.h).
// Probes are refreshed in the same calls (published_probes; docs/runtime.md "Probes"); the voxel
// exitance is computed from what texels show, on request (published_voxel_exitance).
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "exitance/formats/bundle_manifest.h"
#include "exitance/formats/probe_grid.h"
#include "exitance/runtime/vulkan/device_probe_buffer.h"
#include "exitance/runtime/vulkan/device_voxel_exitance.h"
#include "exitance/runtime/world_box.h"
#include "exitance/formats/scene_file.h"
#include "exitance/formats/sparse_voxel_octree.h"
#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/integrator_settings.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/core/work_share.h"
#include "exitance/runtime/refresh/scene_edits.h"
#include "exitance/runtime/scene_file_conversion.h"
#include "exitance/runtime/vulkan/vulkan_integrator.h"

namespace exitance {

// Bad input: a missing or malformed manifest, scene.bin or svo.bin, an impossible option or edit.
// The message names the file (or call), the element and the problem, on one line.
class BundleInputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct RefreshSessionOptions {
  VulkanDeviceOptions device;    // device_index, validation, or an adopted engine device
  std::optional<uint64_t> seed;  // default: the bake's (manifest settings.seed)
  // After a local edit, the texels near it get this many samples before the others get any
  // (texels_near_change.h); 0: every pass takes every texel. 32 rather than 16: texels an edit
  // covered show their change only after a run of zeros long enough (publishing_rule.h), ~20-30 where
  // their kept samples vary most (H200, city block moved: 0.022 -> 0.00034 relMSE after 6 frames).
  uint32_t priority_samples = 32;
  // Start from the bundle's baked lightmap (refresh/baked_lightmap.h): published_lightmap() shows it
  // until refreshed samples are better (published_estimate.h), and the first light edit is estimated
  // as a change from it. false: every texel starts with nothing, as before issue 32.
  bool start_from_baked = true;
  // Keep the estimate per light layer (exitance/common/light_layers.h; docs/runtime.md "Light
  // layers"), so that an edit that only scales a light's emission (intensity, colour,
  // emissiveFactor, emissiveStrength, a constant sky's colour) scales its layer with 0 rays and
  // keeps every sample. Device memory: 24 bytes per layer and texel for each estimate kept.
  bool light_layers = true;
  // What texels showed before (at open: the baked lightmap, whose bundle holds no light layers) has
  // no split by light until replaced by estimates that have one: a scaling edit scales it by the
  // accumulation's split, once the accumulation has this many samples per texel (its split is
  // noisy before); with fewer, such an edit takes the other paths (a change estimate, a restart).
  uint32_t proportional_split_samples = 256;
  // Refresh the bundle's light probes in the same frames (docs/runtime.md "Probes"): each refresh
  // call with a time budget gives the next batch of probes a stratified set of samples (at most
  // `probe_budget_share` of the budget, from the measured cost), up to the bake's probe_spp; an edit
  // that only scales lights scales their light layers (with light_layers), every other edit starts
  // them again; published_probes() shows them. Off: probes stay as baked.
  bool refresh_probes = true;
  double probe_budget_share = 0.25;
  // Light subpaths (bake --light-paths on; docs/runtime.md "Light paths"): each pass of the
  // progressive refresh traces a pool of subpaths from the lights and the sky, and every texel
  // path's vertex connects to one of them, weighted by MIS: light entering through narrow openings
  // (a door ajar) converges several times sooner. Each batch traces its own pool (keyed by the
  // pass's first sample), so the result depends on how calls split the samples, not only on the
  // seed. The refreshed probes' sets connect too (a pool per set).
  bool light_subpaths = false;
  double light_subpaths_per_sample = IntegratorSettings{}.light_subpaths_per_sample;  // (0, 64]
  // Filter the indirect light of what is shown in texture space, with this window radius in texels
  // (1 to 16; 0: off, the default): RefreshSession::set_denoise_radius.
  int denoise_radius = 0;
};

// Edits that change at most this many punctual lights (counted against the base) are estimated as
// a change (RefreshSession::apply_edits); more, and the accumulation restarts.
constexpr uint32_t kMaxChangedLights = kMaxChangedLightPairs;  // gpu_layout.h

// What one refresh() call may spend; it ends at whichever limit comes first. A call with neither
// limit set adds what the sample cap allows.
struct RefreshBudget {
  double milliseconds = 0;             // wall-clock time of the call; 0 = no time limit
  uint32_t max_samples_per_texel = 0;  // cap on the accumulated samples; 0 = no cap
  // Work of the call in texel-samples (a pass of n samples over m texels is n * m); 0 = no limit.
  // Unlike milliseconds, deterministic: the same calls give the same results on any machine. Less
  // than one sample of the texels refreshed is one sample of that many of them (the next call goes
  // on from there), as a millisecond budget shorter than one sample is.
  uint64_t texel_samples = 0;
};

struct RefreshReport {
  double milliseconds = 0;          // this call
  uint64_t rays = 0;                // this call
  uint32_t samples_added = 0;       // to samples_per_texel, this call
  uint32_t samples_per_texel = 0;   // every texel has at least this many since the last edit or restart
  uint32_t prioritized_texels = 0;  // texels near the last edit that this call refreshed first (0: none)
  bool capped = false;              // the sample cap is reached: further calls add nothing
  uint64_t probe_rays = 0;          // this call's probe samples' rays (not in `rays`)
  uint32_t probes_refreshed = 0;    // probes that got a stratified set this call
  uint32_t probe_samples = 0;       // every probe has at least this many since the last edit (or open)
};

// Where the last RefreshSession::apply_edits call spent its time, in milliseconds (benchmarks).
struct EditTimings {
  double scene = 0;        // validating and applying the edits: host scene, lighting scene (light and material uploads), probes restarted
  double texels = 0;       // a moved instance's texels: out of their grid cells, the unocclude step near its bounds
  double near_texels = 0;  // finding the texels near the change (texels_near_change.h): what was left after the uploads and the publish, which it runs beside
  double uploads = 0;      // a moved instance's uploads (run beside `texels`): what was left to wait for, and the texels'
  double publish = 0;      // keeping what texels showed, on the device (publish.comp)
  double restart = 0;      // starting the accumulation again (a restart or a change estimate), or scaling light layers
  bool scaled_light_layers = false;  // the edit only scaled lights: their layers were scaled, no sample was dropped
  // Of all of the above: device submissions waited for, and the milliseconds spent waiting.
  uint64_t device_submissions = 0;
  double device_wait = 0;
};

// Where RefreshSession::open spent its time, in seconds (benchmarks; exitance-relight --json
// seconds.load_split).
struct OpenTimings {
  double read = 0;            // manifest, scene.bin (read and restored), svo.bin
  double lighting_scene = 0;  // the lighting scene (records, light CDFs) over scene.bin's BVH
  double device = 0;          // the Vulkan backend: what was left to wait for of the device (made beside `read`), kernels
                              // compiled (or found in the driver's cache), scene uploaded
  double indices = 0;         // the texel grid, each instance's texels, the BVH links, the texel list: built on a
                              // thread of their own while the device is made; what was left to wait for
  double texels = 0;          // the texels' start points uploaded, the accumulation cleared
  double baked = 0;           // the baked lightmap read (EXR pages) and uploaded
  double publish = 0;         // the first publish (pipeline and memory the first edit reuses)
};

struct KeptProbe;  // refresh/published_probes.h

class RefreshSession {
 public:
  // Reads manifest.json, scene.bin and (when listed) svo.bin from `bundle`, builds the lighting
  // scene and creates the Vulkan backend on it. Throws BundleInputError for bad input,
  // std::runtime_error when no usable Vulkan device exists.
  static std::unique_ptr<RefreshSession> open(const std::string& bundle, const RefreshSessionOptions& options = {});
  ~RefreshSession();
  RefreshSession(const RefreshSession&) = delete;
  RefreshSession& operator=(const RefreshSession&) = delete;

  // Applies `edits` (scene_edits.h, docs/edits.md) to the session's scene, the device's copy of it
  // and scene.bin as write_refreshed_bundle will write it, then restarts the accumulation, so no
  // texel keeps a value from before the edit. All or nothing: throws SceneEditError (one line
  // naming the edit and the problem) with the session unchanged. std::runtime_error on device
  // failure. Nothing is copied whole: edits are validated on copies of the scene's small parts and
  // the moved instances' triangles, then applied in place (apply_scene_edits_in_place); a moved
  // instance refits only its BVH leaves and the nodes above them, and uploads only those, its
  // triangles and the start points of the texels that moved (its own, and those unocclude placed
  // again near its bounds).
  //
  // Edits that change only punctual lights (position, direction, cone, intensity, colour; at most
  // kMaxChangedLights of them since the base) do not restart E/pi: the accumulation becomes an
  // estimate of the change of E/pi from the base (what was published before the first such edit),
  // the same paths with each vertex adding the edited lights' direct light as edited minus as it was
  // (path.h punctual_change_rays), so texels that no edited light reaches keep their value exactly.
  // lightmap() is then that change; refreshed_lightmap() is base + change.
  //
  // Before both: with light layers (RefreshSessionOptions::light_layers), edits that only scale
  // lights' emission (refresh/light_layer_edits.h) scale the accumulation's and the previous
  // estimate's light layers with 0 rays and keep every sample (last_edit_timings().scaled_light_layers).
  EditEffects apply_edits(const std::vector<SceneEdit>& edits);
  const EditTimings& last_edit_timings() const;
  const OpenTimings& open_timings() const;
  // Drops every accumulated sample; the next refresh starts at sample 0.
  void restart();
  RefreshReport refresh(const RefreshBudget& budget);
  // The whole lightmap in the per-bounce mode (seed 003; core/per_bounce_bake.h) on the session's
  // device, at `spp` samples per texel per bounce (0: until the budget) within `time_budget_seconds`
  // (0: none), with the bake's --first-bounce; not progressive: it replaces what lightmap() returns
  // until the next restart, edit or refresh() call (which starts the progressive accumulation
  // again). Throws std::invalid_argument for a bundle with directional layers (per-bounce passes
  // estimate no L1) or without a bound.
  // `caches_on_host`: the layer caches built on the host and uploaded (the path before the device
  // built them; the same results bit for bit), for A/B timing.
  // Returns the result lightmap() returns, by reference, as bake_path.
  const LightmapEstimate& bake_per_bounce(uint32_t spp, double time_budget_seconds, bool caches_on_host = false);
  // Whether lightmap() holds a bake_per_bounce() result.
  bool per_bounce() const;
  // The whole lightmap by grid-guided path tracing (--guiding grid, issue 11) on the session's
  // device: one bake, whose learned table swaps between its passes, so not progressive; otherwise
  // as bake_per_bounce (it replaces what lightmap() returns until the next restart, edit or refresh).
  // `mode`: Grid, Svo (the bundle's svo.bin is the octree; its exitance seeds the first fields) or
  // Auto (grid guiding where its measured pilot says it pays, core/guiding_choice.h; the estimate's
  // guiding_* fields say what it chose).
  const LightmapEstimate& bake_guided(uint32_t spp, double time_budget_seconds, float guiding_mix = 0.5f,
                                      GuidingMode mode = GuidingMode::Grid);
  // Whether lightmap() holds a bake_guided() result.
  bool guided() const;
  // The whole lightmap by unguided path tracing in one run, as bake --backend vulkan runs it (ramped
  // passes, not progressive frames); otherwise as bake_guided. `share`: this process's share of a
  // split bake (core/work_share.h: the texel range bake under mpirun gives its rank); null: every
  // texel. relight --share runs one rank's share alone, to measure how a split balances.
  // Returns the result lightmap() returns, by reference (valid until the next restart, edit or
  // refresh: a million texels' estimate is ~100 MB).
  // `emitter_guiding`: next-event estimation guided by emitter distributions learned during the run
  // (bake --emitter-guiding on; one process only). `light_subpaths`: the texels' paths also connect
  // to light subpaths (bake --light-paths on; not with emitter guiding on this backend).
  const LightmapEstimate& bake_path(uint32_t spp, double time_budget_seconds, WorkShare* share = nullptr,
                                    bool emitter_guiding = false, bool light_subpaths = false);

  // The lightmap accumulated since the last edit or restart (a read-back: it waits for the device);
  // after a light edit estimated as a change (changed_lights() > 0), that change.
  LightmapEstimate lightmap() const;
  // The unbiased estimate of the current scene: lightmap(), or base + change after light edits.
  LightmapEstimate refreshed_lightmap() const;
  // Edited punctual lights the accumulation estimates the change of (0: it estimates E/pi).
  uint32_t changed_lights() const;
  // Whether open() took the bundle's baked lightmap as the starting state (refresh/baked_lightmap.h).
  bool started_from_baked() const;
  // What an engine shows, and what write_refreshed_bundle and the C API's read_page publish: per
  // texel, of what it showed before the last edit (at open, the baked lightmap) and the refreshed
  // estimate, the one with the lower estimated error (published_estimate.h): never a value with
  // fewer than 2 refreshed samples, and a texel no change reaches keeps its value. A whole run
  // (bake_per_bounce, bake_guided, bake_path) is shown wherever it has samples.
  LightmapEstimate published_lightmap() const;
  // published_lightmap() with light layers that add up to its totals, for write_refreshed_bundle:
  // exact where what is published keeps a split by light; texels that show an estimate without one
  // (the baked lightmap of a bundle without layers) split in proportion to the accumulation's split
  // per channel (a channel the accumulation has 0 of goes to the sky's layer), once the accumulation
  // has RefreshSessionOptions::proportional_split_samples. nullopt without light layers, during a
  // change estimate whose base has no split, or before that many samples.
  std::optional<LightmapEstimate> published_lightmap_by_light() const;
  // The texture-space filter of the indirect light (docs/runtime.md "Filtered indirect light"): from
  // now on what is shown (shown_lightmap: read_page, the page images, published_voxel_exitance,
  // write_refreshed_bundle) has each texel's indirect light averaged over atlas neighbours on the
  // same surface within `radius` texels (bundle/indirect_denoise.h's filter, run on the device), its
  // direct light as estimated; 0 turns it off. What texels publish (published_lightmap) and every
  // rule that keeps or replaces it are unchanged: the filter only shapes what is shown. Throws
  // std::invalid_argument (nothing changed) for a radius outside 0 to 16 and, for a radius > 0, on a
  // bundle baked with L1 layers (not split into direct and indirect light).
  void set_denoise_radius(int radius);
  int denoise_radius() const;
  // What an engine sees: published_lightmap() with its indirect light filtered where a denoise radius
  // is set (then without L1 sums or light layers), else published_lightmap() itself. `counts`: what
  // the filter did (left alone when it is off).
  LightmapEstimate shown_lightmap(DeviceDenoiseCounts* counts = nullptr) const;
  // What shown_lightmap() holds, written into one RGBA32F device image per atlas page (E/pi,
  // coverage in A, gutters dilated `dilation_texels` deep: the values assemble_lightmap_pages gives,
  // bit for bit), with no read-back; the images stay the same objects between calls.
  const DevicePageImages& publish_page_images(int dilation_texels);
  // How deep pages dilate colour into the gutter, as bake writes them: twice the bake's chart
  // padding, at least 2 (read_page, the page images and write_refreshed_bundle use it).
  int page_dilation_texels() const;
  // Page `page` of the last publish_page_images read back: RGBA floats, row 0 at the top.
  std::vector<float> read_page_image(size_t page) const;
  // Samples every texel has since the last edit or restart.
  uint32_t samples_per_texel() const;
  // The texels the last edit prioritized (G-buffer indices); empty when it was not local.
  const std::vector<uint32_t>& texels_near_last_edit() const;
  // Estimated relMSE of `estimate` against its converged value, as bench/time_to_error.cpp defines
  // relMSE (mean over live texels and channels of err^2 / (r^2 + 1e-3)), from the per-texel
  // sample variances: v / (max(0, m^2 - v) + 1e-3) with m the mean and v its variance (m^2 - v
  // estimates r^2 without the noise m^2 carries). Texels with fewer than 2 samples are left out;
  // infinity when no texel has 2.
  static double estimated_relative_mse(const LightmapEstimate& estimate);
  // The probes' incident radiance (usable probes of the grid, in grid order) with `spp` rays each:
  // a whole run of its own (write_refreshed_bundle), not the refreshed probes below.
  ProbeEstimate probe_estimate(uint32_t spp);
  // The probe grid as probes.bin stores it (docs/bundle.md), with what the probes show now: per
  // usable probe, the refreshed estimate where the publishing rule prefers it to what the probe
  // showed before (docs/runtime.md "Probes"; published_probes.h), else that (at open the bundle's
  // probes.bin, replaced at as many samples as it has). Empty (no probes) when the bundle has no
  // probe grid. A read-back of the probes' sums.
  formats::ProbeGrid published_probes() const;
  // Probes refreshed since the last edit (or open), and the fewest samples one of them has.
  uint32_t probe_samples() const;
  // What the probes show (published_probes()'s values, bit for bit) written into a device buffer of
  // 27 floats per probe of the grid, in probes.bin's order (0 for probes not in use), and the
  // timeline semaphore value to wait on: no read-back (docs/runtime.md "Probes"). The buffer is the
  // same on every call and lives as long as the session. std::invalid_argument when the session
  // refreshes no probes (refreshes_probes()).
  const DeviceProbeBuffer& publish_probe_buffer();
  std::vector<float> read_probe_buffer() const;  // the last publish_probe_buffer read back (tests, tools)
  // The voxel exitance of what texels show (published_voxel_exitance()'s values before their
  // half-float encoding) computed on the device into a buffer of 6 floats per node of svo.bin, and
  // the timeline semaphore value to wait on: no read-back (docs/runtime.md "Voxel exitance"). Where
  // each texel deposits is worked out on the host at the first call and again after an edit moved
  // texels or changed materials. std::invalid_argument when the bundle has no svo.bin.
  const DeviceVoxelExitance& publish_voxel_exitance();
  std::vector<float> read_voxel_exitance() const;  // the last publish_voxel_exitance read back (tests, tools)
  // Whether the session refreshes the bundle's probes (RefreshSessionOptions::refresh_probes, and
  // the bundle has a probe grid and probes.bin's entry).
  bool refreshes_probes() const;
  // What the probes show, for a report: how many show their refreshed estimate, and the mean over
  // the probes whose shown value has a known variance (refreshed, or kept from a refreshed
  // estimate) of their L0's estimated relMSE, sum_c v_c / (sum_c max(0, m_c^2 - v_c) + 1e-3) as
  // estimated_relative_mse does for texels (NaN when none has one). A read-back of the probes' sums.
  struct ProbeErrors {
    uint32_t probes = 0, showing_refreshed = 0, with_variance = 0;
    double estimated_relative_mse = 0;
  };
  ProbeErrors probe_errors() const;
  // The share of each refresh call's time budget the probes get from now on (RefreshSessionOptions::
  // probe_budget_share), in [0, 1]; 0: no probe is refreshed (each keeps showing what it shows).
  // Throws std::invalid_argument outside [0, 1] (nothing changed).
  void set_probe_budget_share(double share);
  // Light subpaths (RefreshSessionOptions::light_subpaths) from the next pass on: `on` makes every
  // pass of the progressive refresh (and each refreshed probe set) connect to a pool of subpaths,
  // `per_sample` of them per texel sample; off makes the passes plain path tracing again. Samples
  // already taken keep the estimator they were taken with (each is unbiased, so their mean stays
  // so). A change estimate in progress traces none (its paths add only the edited lights' direct
  // light); the accumulation after it does. Throws std::invalid_argument (nothing changed) for
  // `per_sample` outside (0, 64].
  void set_light_subpaths(bool on, double per_sample = IntegratorSettings{}.light_subpaths_per_sample);
  // The bundle's sparse voxel octree with the radiant exitance of what texels show now
  // (shown_lightmap; fill_svo_exitance, as write_refreshed_bundle writes svo.bin), without
  // writing a bundle; nullopt when the bundle has no svo.bin. A read-back and a host pass over the
  // texels (0.1 s at 1 M texels on the H200's host: bench/results/host-stages.md).
  std::optional<formats::SparseVoxelOctree> published_voxel_exitance() const;

  const std::string& bundle() const;
  const formats::BundleManifest& manifest() const;
  // scene.bin's records of the session's scene: as read, or encoded from the edited scene (throws
  // formats::FormatError if that cannot be stored: not expected, edits add nothing scene.bin lacks).
  const formats::SceneFile& scene_file() const;
  const PersistedScene& persisted() const;
  const LightingScene& lighting_scene() const;
  const formats::SparseVoxelOctree* svo() const;  // null when the bundle has none
  const IntegratorSettings& settings() const;     // the bake's path settings, with the session's seed
  VulkanIntegrator& integrator();

  struct State;

 private:
  explicit RefreshSession(std::unique_ptr<State> state);
  void end_change_estimate();
  // An edit: what probes show is kept as what they showed before, and their refresh starts again,
  // nearest the points and boxes first (none: in the grid's order), those near them to the target first.
  // `as_change`: the accumulation has just started a change estimate of the lights; the probes
  // estimate the same change from what they showed at its first edit.
  void restart_probes(const std::vector<Vec3>& near_points = {}, const std::vector<WorldBox>& near_boxes = {},
                      bool as_change = false);
  // An edit that only scaled lights (factors as scale_light_layers'): the probes' sums scaled per
  // light layer on the device and what they showed before by their split, every sample kept;
  // restart_probes() where the probes keep no light layers.
  void scale_probes(const std::vector<Vec4>& factors);
  // published_probes() from a read-back `refreshed` (empty: none refreshed); `refreshed_shown`, per
  // refreshed probe, whether it shows its refreshed estimate (during a change estimate: the base, or
  // the base plus the change); `records` (may be null), per refreshed probe, what it shows with the
  // samples and variance behind it.
  formats::ProbeGrid published_probes(const ProbeEstimate& refreshed, std::vector<bool>* refreshed_shown,
                                      std::vector<KeptProbe>* records = nullptr) const;
  // `texels_as_before`: the G-buffer's texels are those of the accumulation's last start (no
  // instance moved): not uploaded again.
  void restart(bool texels_as_before);
  // What texels publish now (published_lightmap), composed in device memory; `clear_accumulation`:
  // the accumulation's sums cleared in the same submission (apply_edits, which starts it again).
  // `light_layers`: compose the light layers too (where what is published has a split by light to
  // keep: published_split_by_light()); page images and read-backs of totals need none.
  PublishedLightmap publish_on_device(bool clear_accumulation = false, bool light_layers = false) const;
  // publish_on_device(), then filtered on the device where a denoise radius is set (`totals_only`:
  // the filtered estimate's layers not written, for the page images).
  std::shared_ptr<DeviceLightmap> shown_on_device(DeviceDenoiseCounts* counts = nullptr, bool totals_only = false) const;
  // Whether what publish_on_device gives now has light layers that split its totals by light.
  bool published_split_by_light() const;
  // An edit that only scaled lights (light_layer_edits.h): the accumulation and previous scaled per
  // layer with 0 rays, every sample kept (a previous estimate without a split by light, as the
  // baked lightmap, in proportion to the accumulation's split); false (nothing done) during a change
  // estimate, after a per-bounce run (no light layers), or while the accumulation is too young to
  // scale an unsplit previous estimate (RefreshSessionOptions::proportional_split_samples).
  bool scale_light_layers(const std::vector<Vec4>& factors, bool punctual_only);
  std::unique_ptr<State> state_;
};

}  // namespace exitance
