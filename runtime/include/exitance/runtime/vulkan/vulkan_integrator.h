// Vulkan compute backend (DESIGN §5): a wavefront path tracer of lightmap texels over a LightingScene,
// computing path.h's estimator (runtime/common), the same code the CPU reference runs, so both agree
// within statistical error. Stages: generate -> extend (closest hit) -> shade (emission + MIS, NEE,
// continuation, Russian roulette) -> connect (shadow rays, any hit); see runtime/src/vulkan/.
// Light probes (bake_probes) run through the same kernels.
#pragma once
#include <cstdint>
#include <functional>
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "exitance/runtime/core/integrator.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/texel_gbuffer.h"
#include "exitance/runtime/vulkan/vulkan_device_failure.h"
#include "exitance/runtime/vulkan/device_page_images.h"
#include "exitance/runtime/vulkan/device_probe_buffer.h"
#include "exitance/runtime/vulkan/device_voxel_exitance.h"
#include "exitance/runtime/bundle/texel_exitance.h"
#include "exitance/runtime/vulkan/vulkan_external_device.h"

namespace exitance {

enum class VulkanDeviceType { Other, Integrated, Discrete, Virtual, Cpu };
const char* to_string(VulkanDeviceType type);

struct VulkanDeviceInfo {
  uint32_t index = 0;  // position in vkEnumeratePhysicalDevices; what VulkanDeviceOptions::device_index takes
  std::string name;
  VulkanDeviceType type = VulkanDeviceType::Other;
  uint32_t api_version = 0;
  bool usable = false;          // has every feature the backend needs (compute queue, int64, fp64, subgroup ballot)
  std::string missing_feature;  // why not, when !usable
};

// Lists the Vulkan physical devices; empty when there is no loader, no driver or no device.
std::vector<VulkanDeviceInfo> enumerate_vulkan_devices();

// BVH4 node layout in GPU memory: 112-byte float nodes, or 64-byte nodes with 8-bit quantized
// child bounds (conservative). Automatic: quantized on CPU devices (lavapipe), float on GPUs.
enum class VulkanNodeLayout { Automatic, Float, Quantized };

struct VulkanDeviceOptions {
  // Set: the backend adopts this device (vulkan_external_device.h) and creates none; device_index
  // and validation must be left at their defaults (the engine's instance decides validation).
  std::optional<VulkanExternalDevice> external_device;
  int device_index = -1;   // -1: prefer a discrete GPU, then integrated, then any (lavapipe)
  bool validation = false; // enable VK_LAYER_KHRONOS_validation + a debug messenger
  // Receives every validation/debug message (warnings and errors), including those at teardown.
  std::function<void(const std::string&)> on_validation_message;
  // Paths in flight = threads of the largest dispatch; 0 = automatic: on a GPU the most, up to
  // 16 Mi, whose ~1.7 GB per 4 Mi stays within an eighth of its device memory (4 Mi from 16 GiB,
  // 8 Mi from 32, 16 Mi from 64; 1 Mi below 16 GiB), at most 4 Mi on an engine's adopted device;
  // 16 Ki on a CPU device.
  uint32_t max_paths = 0;
  // Wavefront iterations (shade+generate+connect+extend) recorded per submission; 0 = automatic
  // (32 on a GPU, 8 on a CPU device).
  uint32_t iterations_per_submit = 0;
  // Work items (texel, sample) per batch = paths x this; a batch ends with a drain (the last paths
  // finish while slots idle), so more items per batch means fewer drains, for more result memory
  // (recorded_bounces + 1) x 12 bytes per item. 0 = automatic (4; on the H100 larger batches made
  // the shade stage slower than the drains they saved).
  uint32_t work_items_per_path = 0;
  VulkanNodeLayout node_layout = VulkanNodeLayout::Automatic;
  double fence_timeout_seconds = 20.0;  // a submission that does not finish in this time -> VulkanDeviceFailure
  // Each kernel is dispatched once when the integrator is created, so drivers that compile
  // pipelines at their first dispatch (lavapipe: LLVM, 2-20 s per kernel on 2 loaded cores) do it
  // there, under this bound, and not inside a timed submission. -> VulkanDeviceFailure.
  double compile_timeout_seconds = 300.0;
  // Called with the fraction of kernels compiled (0..1) while the integrator is created; set by
  // tools for their progress bars ("compiling kernels").
  std::function<void(double)> on_compile_progress;
  bool collect_stage_statistics = false;  // timestamps + lane counters per stage (bench only; slower)
};

// Per-stage figures of the last bake (filled when collect_stage_statistics is on), one per named
// kernel launch ("shade: hits, emission, next-event, continuation", ...) in the order of their first
// launch, then "rays: primary" and "rays: bounce".
struct VulkanStageStatistics {
  std::string stage;
  double seconds = 0;        // GPU time summed over all dispatches of the stage
  uint64_t items = 0;        // queue entries processed (paths or rays)
  uint64_t rays = 0;         // rays traced by the stage
  double lane_efficiency = 0;  // active lanes / launched lanes (traversal stages: inside the traversal loop)
};

// A lightmap estimate in device memory (runtime/src/vulkan/device_lightmaps.h): what the runtime
// keeps of what texels showed before an edit, and what they publish, without reading it back.
class DeviceLightmap;

// Which rule VulkanIntegrator::publish applies (exitance/common/publishing_rule.h).
enum class PublishMode {
  Accumulation,  // the progressive accumulation as it is (nothing was shown before it)
  Restart,       // refresh/published_estimate.h publish_restart(previous, accumulation)
  Change,        // publish_change(previous, base, accumulation): the accumulation is a change estimate
};

struct PublishedLightmap {
  std::shared_ptr<DeviceLightmap> lightmap;
  uint64_t single_sample_texels = 0;  // published texels with one sample (no variance)
  uint64_t sampled_texels = 0;        // with two or more
};

// What VulkanIntegrator::denoise_indirect filtered: texels with samples, and the neighbours with a
// weight > 0 summed over them (each texel itself included).
struct DeviceDenoiseCounts {
  uint64_t texels = 0;
  uint64_t neighbours = 0;
};

// A Vulkan device made before its scene is known (instance, physical device chosen, logical device,
// or an adopted one wrapped): VulkanIntegrator::prepare_device makes it, so that a caller can make it
// on a thread of its own while it reads the scene (RefreshSession::open), and create() takes it.
struct PreparedVulkanDevice;

class VulkanIntegrator final : public Integrator {
 public:
  // Uploads the scene (its BVH4 as built by the offline stage or read from scene.bin). Throws
  // std::runtime_error when no usable Vulkan device exists (or the adopted one lacks a feature), and
  // for scenes the backend does not support yet (environment-map skies): never
  // a silently wrong result. The integrator keeps no reference to `scene`.
  static std::unique_ptr<VulkanIntegrator> create(std::shared_ptr<const LightingScene> scene,
                                                  const VulkanDeviceOptions& options = {});
  // The same on a device prepare_device made with the same options (none: made here).
  static std::unique_ptr<VulkanIntegrator> create(std::shared_ptr<const LightingScene> scene, const VulkanDeviceOptions& options,
                                                  std::shared_ptr<PreparedVulkanDevice> device);
  // Throws std::runtime_error when no usable Vulkan device exists (as create()). Any thread.
  static std::shared_ptr<PreparedVulkanDevice> prepare_device(const VulkanDeviceOptions& options = {});
  ~VulkanIntegrator() override;
  VulkanIntegrator(const VulkanIntegrator&) = delete;
  VulkanIntegrator& operator=(const VulkanIntegrator&) = delete;

  // Same contract and fields as CpuReferenceIntegrator::bake. Supported settings: spp (0 needs a
  // time budget), time_budget_seconds, target_relative_error (checked between batches),
  // max_bounces, seed, recorded_bounces, russian_roulette_start, safety_bounce_cap, progress.
  // Throws std::runtime_error on device loss, out of memory or a fence timeout.
  LightmapEstimate bake(const TexelGBuffer& gbuffer, const IntegratorSettings& settings) const override;

  // Light probes: same contract and fields as CpuReferenceIntegrator::bake_probes (ProbeEstimate:
  // stratified sphere rays, incident radiance projected to L2 SH), same random streams. Supported
  // settings: spp (0 needs a time budget), time_budget_seconds (checked only when every probe has a
  // complete stratified set), max_bounces, seed, russian_roulette_start, safety_bounce_cap, progress.
  // Independent of bake(); throws as bake() does.
  ProbeEstimate bake_probes(const std::vector<Vec3>& positions, const IntegratorSettings& settings) const override;
  std::string backend_name() const override { return "vulkan"; }

  // Progressive probes kept on the device (the runtime's refresh; vulkan/probe_refresh.h): the same
  // estimator and random streams as bake_probes, a stratified set (kProbeStratifiedSetSize samples)
  // of the next batch of probes per refresh_probe_set call, round robin, up to `target_samples` each,
  // so that N samples of a probe are bake_probes' N samples with the same seed. Their own buffers:
  // bake_probes and the lightmap's accumulation do not disturb them, nor they those. start clears
  // the sums; clear_probe_refresh clears them again (an edit). Settings used as by bake_probes.
  // `light_layers`: the scene's light layers, kept per probe too (0: none; fewer where they would
  // not fit the device: probe_refresh_light_layers says).
  void start_probe_refresh(const std::vector<Vec3>& positions, int light_layers = 0);
  // `order`: the probes nearest a local edit first (ProbeRefresh::clear); empty: their own order.
  // `as_change`: the probes' samples estimate the change that the accumulation's change estimate
  // (start_progressive_change, called first) estimates for texels, into the same light layers.
  void clear_probe_refresh(const std::vector<uint32_t>& order = {}, size_t priority = 0, bool as_change = false);
  bool probe_refresh_as_change() const;  // the probes' sums are a change estimate's
  int probe_refresh_light_layers() const;
  // An edit that only scaled lights (factors as scale_light_layers'): the probes' sums scaled on the
  // device, 0 rays, every sample kept. Needs probe_refresh_light_layers() == factors.size().
  void scale_probe_layers(const std::vector<Vec4>& factors);
  // One light layer's sums per probe (with the probes' counts): a read-back of that layer alone.
  ProbeEstimate probe_refresh_layer(int layer) const;
  // At most `max_probes` probes (0: as many as one batch holds); `refreshed`: how many got their set.
  uint64_t refresh_probe_set(const IntegratorSettings& settings, uint32_t target_samples, size_t max_probes = 0,
                             size_t* refreshed = nullptr);
  // A read-back: totals, squared L0 sums and counts; with `with_layers`, the light layers' sums too.
  ProbeEstimate probe_refresh_estimate(bool with_layers = false) const;
  uint32_t probe_refresh_samples() const;         // the fewest samples of a probe
  uint32_t probe_refresh_most_samples() const;    // the most (0: none refreshed)

  // Progressive accumulation kept on the device between calls (the runtime's refresh). start
  // uploads the texels and clears their sums; add_samples adds `samples` to every texel, sample
  // indices continuing from the last call (so N samples in any number of calls are bake()'s N
  // samples with the same seed), and returns the rays traced; progressive_estimate downloads the
  // sums. Settings used: seed, max_bounces, recorded_bounces, russian_roulette_start,
  // safety_bounce_cap, sampling_strategy. bake() ends an accumulation (start again after it);
  // bake_probes in between does not. Throws as bake() does; std::logic_error before a start.
  // `texels_as_before`: `gbuffer`'s texels are those of the running accumulation (an edit that moved
  // no instance): they are not uploaded again, only the sums cleared.
  // `accumulation_cleared`: the last publish cleared the sums (publish(..., true)) and nothing ran
  // since: no submission to clear them again.
  void start_progressive(const TexelGBuffer& gbuffer, const IntegratorSettings& settings, bool texels_as_before = false,
                         bool accumulation_cleared = false);
  // The running progressive accumulation's light subpaths as `settings` asks (light_subpaths,
  // light_subpaths_per_sample) from its next pass on: pools made, or dropped so that its passes path
  // trace; a change estimate's passes trace none either way. Nothing before a start. Throws as
  // start_progressive does for settings it refuses.
  void set_progressive_light_subpaths(const IntegratorSettings& settings);
  // A progressive accumulation of the change of E/pi from edited punctual lights (path.h
  // punctual_change_rays: the same paths, each vertex adding an edited light's direct light as edited
  // minus as it was; no emission, no sky). `edited`: the scene as update_lights last uploaded it;
  // `pairs`: per edited light its record in `edited` then its record at the base (at least one
  // pair). Uploads `edited`'s punctual records, the pairs after them and the punctual CDF in one
  // submission. Otherwise as start_progressive; the next start_progressive estimates E/pi again.
  // `pair_layers`: with light layers, each pair's light layer, where its change is summed.
  void start_progressive_change(const TexelGBuffer& gbuffer, const IntegratorSettings& settings, const LightingScene& edited,
                                const std::vector<GpuPunctualLight>& pairs, bool texels_as_before = false,
                                bool accumulation_cleared = false, const std::vector<uint32_t>& pair_layers = {});
  // What texels publish now, composed on the device from the progressive accumulation and the
  // estimates given (null where `mode` reads none; shaped as the accumulation), into a new device
  // estimate; waits for the device (a dispatch, no read-back of the lightmap). std::logic_error
  // before a start. `clear_accumulation`: the accumulation's sums cleared in the same submission,
  // for a start_progressive(..., accumulation_cleared = true) right after.
  // `light_layers` false: the published estimate's light layers are not composed (left as they were;
  // what is published has no split by light worth keeping, and copying them costs a read and write
  // of every layer of every texel).
  PublishedLightmap publish(PublishMode mode, const DeviceLightmap* previous, const DeviceLightmap* base,
                            bool clear_accumulation = false, bool light_layers = true);
  // A host estimate into device memory. publish() reads a previous estimate shaped otherwise than
  // the accumulation (texels, recorded layers, sh1) as none.
  std::shared_ptr<DeviceLightmap> upload_lightmap(const LightmapEstimate& estimate);
  // Light layers (IntegratorSettings::light_layers): the progressive accumulation's count (0: none),
  // and an edit that only scaled lights' emission applied to it and to `previous` (shaped as it; null:
  // none), with 0 rays in one submission (shaders/wavefront/scale_light_layers.comp): exactly where
  // the light layers split the totals, and for a previous estimate whose layers do not
  // (`previous_split` false) by the accumulation's split. `factors`: per light layer, rgb and w = 1
  // where scaled. std::logic_error before a start or for another shape.
  int light_layers() const;
  // The scaling kernel made (on lavapipe compiled) now rather than inside the first scaling edit.
  void prepare_light_layer_scaling();
  // Host-visible staging for edits' uploads (`bytes` each for the reused and the next submission's
  // staging, up to 16 MiB) allocated and its pages touched now rather than inside the first edit.
  void reserve_edit_staging(size_t bytes);
  void scale_light_layers(const std::vector<Vec4>& factors, const DeviceLightmap* previous, bool previous_split);
  // `published` (an estimate of `gbuffer`'s texels) with its indirect light filtered in texture space
  // on the device (bundle/indirect_denoise.h's filter: the same weights and arithmetic, equal up to
  // the rounding of exp and sqrt; shaders/wavefront/denoise_indirect.comp), into a device estimate
  // with its texels and recorded layers and no L1 sums or light layers. What the filter reads of the
  // G-buffer is uploaded at the first call and again after a start with other texels;
  // update_texels patches it. One submission, waited for. std::invalid_argument for a radius outside
  // 1 to 16 or an estimate with L1 sums (not split into direct and indirect light).
  // `totals_only`: only the totals and sample counts are written (all write_page_images reads); the
  // result's layers are then not those of the filtered estimate.
  std::shared_ptr<DeviceLightmap> denoise_indirect(const DeviceLightmap& published, const TexelGBuffer& gbuffer, int radius,
                                                   DeviceDenoiseCounts* counts = nullptr, bool totals_only = false);
  // Writes `lightmap` (a published estimate of `gbuffer`'s texels) into one RGBA32F device image per
  // page, gutters dilated `dilation_texels` deep as assemble_lightmap_pages does (the same values
  // bit for bit), after every command submitted to the queue before; waits (bounded). The images
  // are made at the first call (and again only if the pages change) and kept until destruction.
  const DevicePageImages& write_page_images(const DeviceLightmap& lightmap, const TexelGBuffer& gbuffer, int dilation_texels);
  // Page `page` of the last write_page_images read back: RGBA floats, row 0 at the top.
  std::vector<float> read_page_image(size_t page) const;
  // What the refreshed probes show, written into a device buffer of 27 floats per grid probe
  // (vulkan/probe_publishing.h): `grid_index` per refreshed probe its grid slot; `kept` (when not
  // null: uploaded first) kKeptWords per probe of what each showed before and, while the probes
  // estimate a change (probe_refresh_as_change), its base; the rest as
  // RefreshSession::published_probes decides. One submission, waited for; no read-back.
  const DeviceProbeBuffer& write_probe_buffer(size_t grid_probes, const std::vector<uint32_t>& grid_index,
                                              const std::vector<double>* kept, uint32_t switch_samples,
                                              const std::array<float, 3>& band_weight);
  std::vector<float> read_probe_buffer() const;  // the last write_probe_buffer read back
  // The voxel exitance of `lightmap` computed on the device into a buffer of 6 floats per node of
  // `svo` (vulkan/voxel_exitance_publishing.h); `deposits` (when not null: uploaded first, and
  // needed at the first call) where each texel deposits. One submission, waited for; no read-back.
  const DeviceVoxelExitance& write_voxel_exitance(const DeviceLightmap& lightmap, const formats::SparseVoxelOctree& svo,
                                                  const VoxelDeposits* deposits);
  std::vector<float> read_voxel_exitance() const;  // the last write_voxel_exitance read back
  // The device this integrator runs on (its own, or the adopted one): what an engine sharing it needs.
  VulkanExternalDevice vulkan_device() const;
  // A device estimate read back, with the progressive accumulation's rays, seconds and counters.
  LightmapEstimate read_lightmap(const DeviceLightmap& lightmap) const;
  uint64_t add_samples(uint32_t samples);
  // Samples [first_sample, first_sample + samples) of the listed texels only (G-buffer indices, each
  // at most once): the runtime's priorities. The caller keeps each texel's count (add_samples'
  // count is not advanced). std::out_of_range for an index beyond the G-buffer.
  uint64_t add_samples_to(const std::vector<uint32_t>& texels, uint32_t first_sample, uint32_t samples);
  LightmapEstimate progressive_estimate() const;
  uint32_t progressive_samples() const;  // per texel so far; 0 before a start
  std::string device_description() const override;

  // Runtime edits without a rebuild. `edited` is the scene this integrator was created on (or a
  // copy) after set_material / set_punctual_light (lighting_scene.h): update_materials uploads the
  // materials (their power per area), the emitter distribution and flags again; update_lights the punctual lights,
  // their CDF and the constant sky. Geometry and BVH stay (update_geometry moves them). Throws
  // std::invalid_argument when the counts of triangles, materials or lights differ,
  // std::runtime_error as create() for what the backend does not support.
  void update_materials(const LightingScene& edited);
  void update_lights(const LightingScene& edited);
  // update_lights for edits of punctual lights alone: their records and CDF in one submission (the
  // sky, and a sky image, are not uploaded again).
  void update_punctual_lights(const LightingScene& edited);
  // After set_geometry (lighting_scene.h: moved instances, BVH refit, same triangles): uploads the
  // triangles, BVH nodes (float or quantized, as created) and leaf vertex copies, then what
  // update_materials and update_lights upload; no device or pipeline is created again (a buffer
  // only grows when the emitter list does), and a bake afterwards equals one of a fresh integrator
  // on `edited`. Throws std::invalid_argument when the triangle, material or light count or the
  // BVH's node count, leaf slots or stack bound differ.
  void update_geometry(const LightingScene& edited);
  // update_geometry for an edit made in place (RefreshSession): after
  // refresh_moved_triangles_from_source, which returned `changed_nodes` for `moved_triangles`;
  // `emitters_changed` when an emitter was among them, `materials_changed` when the same call also
  // edited materials (refresh_materials_from_source). Uploads only what those change; the device
  // scene then equals update_geometry's.
  void update_moved_geometry(const LightingScene& edited, const Bvh4Links& links, const std::vector<uint32_t>& moved_triangles,
                             const std::vector<uint32_t>& changed_nodes, bool emitters_changed, bool materials_changed = false);
  // The running accumulation's start points of `texels` (G-buffer indices) taken from `gbuffer`
  // again (texels an edit moved), so a later start_progressive(..., texels_as_before = true) traces
  // from where they are now. Nothing before a start. std::out_of_range for an index beyond it.
  void update_texels(const TexelGBuffer& gbuffer, const std::vector<uint32_t>& texels);

  const VulkanDeviceInfo& device() const;
  // Submissions this integrator has waited for, and the seconds spent waiting, so far.
  uint64_t waited_submissions() const;
  double wait_seconds() const;
  uint32_t max_paths() const;
  size_t path_state_bytes_per_path() const;  // SoA path state + queues + shadow rays, per path slot
  size_t bvh_bytes() const;
  uint32_t bvh_node_count() const;
  const std::vector<VulkanStageStatistics>& stage_statistics() const;  // of the last bake

  // Traversal-only throughput: `ray_count` incoherent rays (uniform origins in the scene bounds,
  // uniform directions), closest hit; returns rays per second of GPU time (timestamps).
  double measure_incoherent_traversal(uint32_t ray_count, int repetitions = 5) const;

  struct Impl;

 private:
  explicit VulkanIntegrator(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace exitance
