// The Vulkan backend as an Integrator: owns the device context, the scene on the device, the
// wavefront's kernels and buffers, and one driver per integrator (lightmap texels, probes), which
// run batches through the shared wavefront-batch runner (wavefront_batch.h). The per-bounce mode is
// the core's host loop (core/per_bounce_bake.h) over this backend's layer estimator (bounce_layer_driver.h).
#include "exitance/runtime/vulkan/vulkan_integrator.h"

#include <optional>
#include <stdexcept>

#include "bounce_layer_driver.h"
#include "device_lightmaps.h"
#include "light_layer_scaling.h"
#include "exitance/runtime/core/grid_guiding_cache.h"
#include "exitance/runtime/core/per_bounce_bake.h"
#include "exitance/runtime/core/work_share.h"
#include "gpu_scene.h"
#include "kernel_launches.h"
#include "exitance/common/texture_space_filter.h"
#include "indirect_denoiser.h"
#include "lightmap_page_images.h"
#include "probe_publishing.h"
#include "voxel_exitance_publishing.h"
#include "lightmap_driver.h"
#include "probe_driver.h"
#include "probe_refresh.h"
#include "traversal_benchmark.h"
#include "vulkan_context.h"
#include "wavefront_batch.h"
#include "wavefront_buffers.h"
#include "wavefront_kernels.h"
#include "wavefront_sizes.h"

namespace exitance {
using namespace exitance::vulkan;
namespace {

// Light subpaths add their strategies to path tracing alone, as on the CPU (whose emitter guiding
// also combines): texels, probes and the progressive accumulation refuse the rest alike.
void check_light_subpaths(const IntegratorSettings& settings) {
  if (!settings.light_subpaths) return;
  if (settings.integrator == IntegratorMode::Bounces)
    throw std::invalid_argument("Vulkan backend: --light-paths applies to path tracing, not to --integrator bounces");
  if (settings.guiding != GuidingMode::Off)
    throw std::invalid_argument("Vulkan backend: --light-paths is not combined with --guiding (use --guiding off)");
  if (distributed(settings.work_share))
    throw std::invalid_argument("Vulkan backend: --light-paths runs in one process only, not under mpirun with several ranks");
  if (!(settings.light_subpaths_per_sample > 0 && settings.light_subpaths_per_sample <= 64))
    throw std::invalid_argument("Vulkan backend: light subpaths per sample must be in (0, 64]");
}

vulkan::GuidingScene guiding_scene(const LightingScene& scene, std::shared_ptr<const LightingScene> created) {
  vulkan::GuidingScene g;
  g.lighting = std::move(created);
  g.bounds_lo = scene.bounds_lo;
  g.bounds_hi = scene.bounds_hi;
  g.reference_radiance = GridGuidingCache::reference_radiance(scene);
  return g;
}

}  // namespace

struct PreparedVulkanDevice {
  std::unique_ptr<Context> context;
};

// Members in construction order: each uses those above it, and goes before them.
struct VulkanIntegrator::Impl {
  std::unique_ptr<Context> owned_context;  // made by prepare_device
  Context& context;
  WavefrontSizes sizes;
  GpuScene scene;
  WavefrontKernels kernels;
  WavefrontBuffers buffers;
  StageStatistics statistics;
  WavefrontBatchRunner runner;
  LightmapDriver lightmap;
  ProbeDriver probes;
  ProbeRefresh probe_refresh;
  std::optional<LightmapPublisher> publisher;  // made at the first publish or upload
  std::optional<LightLayerScaler> scaler;      // made at the first scaling edit
  std::unique_ptr<LightmapPageImages> page_images;  // made at the first write_page_images
  std::unique_ptr<ProbePublisher> probe_publisher;  // made at the first write_probe_buffer
  std::unique_ptr<VoxelExitancePublisher> voxel_publisher;  // made at the first write_voxel_exitance
  std::unique_ptr<IndirectDenoiser> denoiser;        // made at the first denoise_indirect
  bool denoiser_stale = false;                       // a start with other texels since it was made
  // The accumulation's change estimate (start_progressive_change): its pairs and their layers, which
  // clear_probe_refresh(..., as_change) gives the probes too; 0 pairs after start_progressive.
  uint32_t change_pairs = 0;
  std::vector<uint32_t> change_layers;
  std::shared_ptr<DeviceLightmap> denoised;          // denoise_indirect's output, reused once let go
  // Device estimates publish() wrote, reused once their holders let go of them (an edit replaces
  // the previous estimate: at 1 M texels ~100 MB not allocated again).
  std::vector<std::shared_ptr<DeviceLightmap>> spare_lightmaps;
  static constexpr size_t kSpareLightmaps = 4;
  // The per-bounce gather reads each triangle's instance and lightmap UVs from here (shared, not a
  // reference to the caller's scene); update_geometry keeps it current.
  std::shared_ptr<const Scene> source;
  std::shared_ptr<const LightingScene> created_on;  // SVO guiding's capture rays

  Impl(std::shared_ptr<const LightingScene> lighting_ptr, const VulkanDeviceOptions& options, std::unique_ptr<Context> made)
      : Impl(*lighting_ptr, options, lighting_ptr, std::move(made)) {}
  Impl(const LightingScene& lighting, const VulkanDeviceOptions& options, std::shared_ptr<const LightingScene> lighting_ptr,
       std::unique_ptr<Context> made)
      : owned_context(std::move(made)),
        context(*owned_context),
        sizes(choose_wavefront_sizes(context, options)),
        scene(context, lighting, sizes.quantized_nodes),
        kernels(context, kernel_stack_bound(sizes, scene.traversal_stack_bound()), sizes.quantized_nodes),
        buffers(context, sizes.paths),
        runner(context, scene, kernels, buffers, statistics, sizes, options.collect_stage_statistics),
        lightmap(runner),
        probes(runner),
        probe_refresh(runner),
        source(lighting.source),
        created_on(std::move(lighting_ptr)) {
    runner.bind_buffers();
    runner.compile_kernels(options.compile_timeout_seconds, options.on_compile_progress);
    lightmap.set_guiding_scene(guiding_scene(lighting, created_on));
  }
};

std::unique_ptr<VulkanIntegrator> VulkanIntegrator::create(std::shared_ptr<const LightingScene> scene,
                                                           const VulkanDeviceOptions& options) {
  return create(std::move(scene), options, nullptr);
}

std::unique_ptr<VulkanIntegrator> VulkanIntegrator::create(std::shared_ptr<const LightingScene> scene,
                                                           const VulkanDeviceOptions& options,
                                                           std::shared_ptr<PreparedVulkanDevice> device) {
  if (!scene) throw std::invalid_argument("Vulkan backend: no scene");
  check_supported_by_vulkan(*scene);
  if (!device) device = prepare_device(options);
  if (!device->context) throw std::invalid_argument("Vulkan backend: a prepared device can make one integrator");
  return std::unique_ptr<VulkanIntegrator>(new VulkanIntegrator(std::make_unique<Impl>(scene, options, std::move(device->context))));
}

std::shared_ptr<PreparedVulkanDevice> VulkanIntegrator::prepare_device(const VulkanDeviceOptions& options) {
  auto prepared = std::make_shared<PreparedVulkanDevice>();
  prepared->context = std::make_unique<Context>(options);
  return prepared;
}

VulkanIntegrator::VulkanIntegrator(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
VulkanIntegrator::~VulkanIntegrator() = default;

LightmapEstimate VulkanIntegrator::bake(const TexelGBuffer& gbuffer, const IntegratorSettings& settings) const {
  if (settings.adaptive) throw std::runtime_error("Vulkan backend: --adaptive on is implemented on the CPU backend only (use --backend cpu)");
  check_light_subpaths(settings);
  if (settings.spp == 0 && !(settings.time_budget_seconds > 0) && !(settings.target_relative_error > 0))
    throw std::invalid_argument("Vulkan backend: spp 0 needs a time budget or a target error");
  if (settings.integrator == IntegratorMode::Bounces) {
    if (settings.directional != DirectionalMode::Off)
      throw std::invalid_argument("Vulkan backend: --directional sh1 applies to path tracing, not to --integrator bounces");
    if (settings.guiding != GuidingMode::Off)
      throw std::invalid_argument("Vulkan backend: guiding applies to path tracing, not to --integrator bounces");
    impl_->lightmap.end_progressive();  // the texel buffers are this bake's now
    impl_->runner.statistics().clear();
    vulkan::BounceLayerDriver layers(impl_->runner, impl_->source, gbuffer, settings, impl_->created_on);
    LightmapEstimate estimate = bake_per_bounce(gbuffer, settings, layers);
    layers.report(estimate.emitter_guiding);
    return estimate;
  }
  return impl_->lightmap.bake(gbuffer, settings);
}

ProbeEstimate VulkanIntegrator::bake_probes(const std::vector<Vec3>& positions, const IntegratorSettings& settings) const {
  if (settings.spp == 0 && !(settings.time_budget_seconds > 0))
    throw std::invalid_argument("Vulkan backend: probes with spp 0 need a time budget");
  check_light_subpaths(settings);
  return impl_->probes.bake(positions, settings, impl_->lightmap.guiding_scene().lighting.get());
}

void VulkanIntegrator::start_probe_refresh(const std::vector<Vec3>& positions, int light_layers) {
  impl_->probe_refresh.start(positions, light_layers);
}
void VulkanIntegrator::clear_probe_refresh(const std::vector<uint32_t>& order, size_t priority, bool as_change) {
  if (as_change && impl_->change_pairs == 0)
    throw std::logic_error("VulkanIntegrator::clear_probe_refresh: a change estimate of the probes needs one of the lightmap");
  if (as_change) impl_->probe_refresh.clear(order, priority, impl_->change_pairs, impl_->change_layers);
  else impl_->probe_refresh.clear(order, priority);
}
bool VulkanIntegrator::probe_refresh_as_change() const { return impl_->probe_refresh.change_pairs() > 0; }
int VulkanIntegrator::probe_refresh_light_layers() const { return impl_->probe_refresh.light_layers(); }
void VulkanIntegrator::scale_probe_layers(const std::vector<Vec4>& factors) { impl_->probe_refresh.scale_layers(factors); }
ProbeEstimate VulkanIntegrator::probe_refresh_layer(int layer) const { return impl_->probe_refresh.read_layer(layer); }
uint64_t VulkanIntegrator::refresh_probe_set(const IntegratorSettings& settings, uint32_t target_samples, size_t max_probes,
                                             size_t* refreshed) {
  check_light_subpaths(settings);
  return impl_->probe_refresh.add_set(settings, target_samples, max_probes, refreshed, impl_->lightmap.guiding_scene().lighting.get());
}
ProbeEstimate VulkanIntegrator::probe_refresh_estimate(bool with_layers) const { return impl_->probe_refresh.read(with_layers); }
uint32_t VulkanIntegrator::probe_refresh_samples() const { return impl_->probe_refresh.least_samples(); }
uint32_t VulkanIntegrator::probe_refresh_most_samples() const { return impl_->probe_refresh.most_samples(); }

void VulkanIntegrator::start_progressive(const TexelGBuffer& gbuffer, const IntegratorSettings& settings, bool texels_as_before,
                                         bool accumulation_cleared) {
  // The progressive accumulation (exitance-relight) adds samples in calls the caller sizes, with no
  // pass where a learned table could swap: guiding runs in bake() only.
  if (settings.guiding != GuidingMode::Off || settings.emitter_guiding)
    throw std::runtime_error("Vulkan backend: guiding runs in whole bakes only, not in progressive accumulation (relight)");
  check_light_subpaths(settings);
  impl_->lightmap.start(gbuffer, settings, 0, texels_as_before, accumulation_cleared);
  impl_->change_pairs = 0;
  impl_->change_layers.clear();
  impl_->denoiser_stale |= !texels_as_before;
}
void VulkanIntegrator::set_progressive_light_subpaths(const IntegratorSettings& settings) {
  check_light_subpaths(settings);
  impl_->lightmap.set_light_subpaths(settings);
}
void VulkanIntegrator::start_progressive_change(const TexelGBuffer& gbuffer, const IntegratorSettings& settings,
                                                const LightingScene& edited, const std::vector<GpuPunctualLight>& pairs,
                                                bool texels_as_before, bool accumulation_cleared, const std::vector<uint32_t>& pair_layers) {
  if (settings.guiding != GuidingMode::Off || settings.emitter_guiding)
    throw std::runtime_error("Vulkan backend: guiding runs in whole bakes only, not in progressive accumulation (relight)");
  if (pairs.empty() || pairs.size() % 2 != 0)
    throw std::invalid_argument("Vulkan backend: a change estimate needs pairs of light records (edited, base)");
  impl_->scene.set_changed_light_pairs(edited, pairs);
  impl_->lightmap.set_guiding_scene(guiding_scene(edited, impl_->created_on));
  if (pairs.size() / 2 > kMaxChangedLightPairs || (!pair_layers.empty() && pair_layers.size() != pairs.size() / 2))
    throw std::invalid_argument("Vulkan backend: at most kMaxChangedLightPairs pairs, each with its light layer");
  impl_->lightmap.start(gbuffer, settings, uint32_t(pairs.size() / 2), texels_as_before, accumulation_cleared, pair_layers);
  impl_->change_pairs = uint32_t(pairs.size() / 2);
  impl_->change_layers = pair_layers;
  impl_->change_layers.resize(impl_->change_pairs, 0);  // without light layers: all in layer 0, unread
  impl_->denoiser_stale |= !texels_as_before;
}
uint64_t VulkanIntegrator::add_samples(uint32_t samples) { return impl_->lightmap.add_samples(samples); }
uint64_t VulkanIntegrator::add_samples_to(const std::vector<uint32_t>& texels, uint32_t first_sample, uint32_t samples) {
  return impl_->lightmap.add_samples_to(texels, first_sample, samples);
}
LightmapEstimate VulkanIntegrator::progressive_estimate() const { return impl_->lightmap.read(); }

PublishedLightmap VulkanIntegrator::publish(PublishMode mode, const DeviceLightmap* previous, const DeviceLightmap* base,
                                            bool clear_accumulation, bool light_layers) {
  const LightmapDriver::Shape shape = impl_->lightmap.shape();
  // An estimate of another shape (a whole run's, with other recorded layers) is nothing to keep.
  auto fits = [&](const DeviceLightmap* e) {
    return e && e->texels == shape.texels && e->layers == shape.layers && e->directional == shape.directional &&
           e->light_layers == shape.light_layers;
  };
  if (mode == PublishMode::Change && !(fits(base) && fits(previous)))
    throw std::logic_error("VulkanIntegrator::publish: a change estimate's base and previous must be shaped as the accumulation");
  if (mode == PublishMode::Restart && !fits(previous)) mode = PublishMode::Accumulation, previous = nullptr;
  if (!impl_->publisher) impl_->publisher.emplace(impl_->context);
  std::shared_ptr<DeviceLightmap> out;
  for (const std::shared_ptr<DeviceLightmap>& spare : impl_->spare_lightmaps)
    if (spare.use_count() == 1 && spare->texels == shape.texels && spare->layers == shape.layers &&
        spare->directional == shape.directional && spare->light_layers == shape.light_layers) {
      out = spare;
      break;
    }
  if (!out) {
    out = std::make_shared<DeviceLightmap>(impl_->context, shape.texels, shape.layers, shape.directional, shape.light_layers);
    if (impl_->spare_lightmaps.size() >= Impl::kSpareLightmaps)  // of another shape, or all in use: the oldest free one goes
      for (auto it = impl_->spare_lightmaps.begin(); it != impl_->spare_lightmaps.end(); ++it)
        if (it->use_count() == 1) {
          impl_->spare_lightmaps.erase(it);
          break;
        }
    if (impl_->spare_lightmaps.size() < Impl::kSpareLightmaps) impl_->spare_lightmaps.push_back(out);
  }
  return impl_->publisher->publish(mode, impl_->buffers.texels, previous, base, std::move(out), clear_accumulation, light_layers);
}

std::shared_ptr<DeviceLightmap> VulkanIntegrator::upload_lightmap(const LightmapEstimate& estimate) {
  if (!impl_->publisher) impl_->publisher.emplace(impl_->context);
  auto lightmap = std::make_shared<DeviceLightmap>(impl_->context, estimate.texels.size(), estimate.recorded_bounces, estimate.has_sh1(),
                                                   estimate.light_layers);
  impl_->publisher->upload(estimate, *lightmap);
  // Kept among the spares: when the caller lets it go (the first edit replaces the baked lightmap),
  // a later publish reuses its memory instead of it being freed inside the edit (freeing ~100 MB
  // of device memory costs milliseconds).
  if (impl_->spare_lightmaps.size() < Impl::kSpareLightmaps) impl_->spare_lightmaps.push_back(lightmap);
  return lightmap;
}

int VulkanIntegrator::light_layers() const { return impl_->lightmap.started() ? impl_->lightmap.shape().light_layers : 0; }

void VulkanIntegrator::prepare_light_layer_scaling() {
  if (!impl_->scaler) impl_->scaler.emplace(impl_->context);
}

void VulkanIntegrator::reserve_edit_staging(size_t bytes) { impl_->context.reserve_staging(bytes); }

void VulkanIntegrator::scale_light_layers(const std::vector<Vec4>& factors, const DeviceLightmap* previous, bool previous_split) {
  const LightmapDriver::Shape shape = impl_->lightmap.shape();
  const ScaledEstimate accumulation{&impl_->buffers.texels, shape.texels, shape.layers, shape.light_layers, shape.directional};
  std::vector<ScaledEstimate> scaled;
  if (previous) {
    const DeviceLightmap* e = previous;
    if (e->texels != shape.texels || e->layers != shape.layers || e->light_layers != shape.light_layers ||
        e->directional != shape.directional)
      throw std::logic_error("VulkanIntegrator::scale_light_layers: an estimate not shaped as the accumulation");
    scaled.push_back({&e->sums, e->texels, e->layers, e->light_layers, e->directional, !previous_split});
  }
  if (!impl_->scaler) impl_->scaler.emplace(impl_->context);
  impl_->scaler->scale(factors, accumulation, scaled);
  impl_->lightmap.scene_changed();  // the passes to come light the edited scene (its sky colour)
}

LightmapEstimate VulkanIntegrator::read_lightmap(const DeviceLightmap& lightmap) const { return impl_->lightmap.read(lightmap); }

const DeviceProbeBuffer& VulkanIntegrator::write_probe_buffer(size_t grid_probes, const std::vector<uint32_t>& grid_index,
                                                              const std::vector<double>* kept, uint32_t switch_samples,
                                                              const std::array<float, 3>& band_weight) {
  if (!impl_->probe_publisher || !impl_->probe_publisher->fits(grid_probes, grid_index)) {
    if (!kept) throw std::logic_error("VulkanIntegrator::write_probe_buffer: the first write needs the kept values");
    impl_->probe_publisher.reset();
    impl_->probe_publisher = std::make_unique<ProbePublisher>(impl_->context, grid_probes, grid_index);
  }
  if (kept) impl_->probe_publisher->set_kept(*kept);
  return impl_->probe_publisher->write(impl_->buffers.refresh_probe_sums, switch_samples, band_weight, probe_refresh_as_change());
}

const DeviceVoxelExitance& VulkanIntegrator::write_voxel_exitance(const DeviceLightmap& lightmap, const formats::SparseVoxelOctree& svo,
                                                                 const VoxelDeposits* deposits) {
  if (!impl_->voxel_publisher) {
    if (!deposits) throw std::logic_error("VulkanIntegrator::write_voxel_exitance: the first write needs the deposits");
    impl_->voxel_publisher = std::make_unique<VoxelExitancePublisher>(impl_->context, svo);
  }
  if (deposits) impl_->voxel_publisher->set_deposits(*deposits);
  return impl_->voxel_publisher->write(lightmap);
}

std::vector<float> VulkanIntegrator::read_voxel_exitance() const {
  if (!impl_->voxel_publisher) throw std::logic_error("VulkanIntegrator::read_voxel_exitance before write_voxel_exitance");
  return impl_->voxel_publisher->read_back();
}

std::vector<float> VulkanIntegrator::read_probe_buffer() const {
  if (!impl_->probe_publisher) throw std::logic_error("VulkanIntegrator::read_probe_buffer before write_probe_buffer");
  return impl_->probe_publisher->read_back();
}

const DevicePageImages& VulkanIntegrator::write_page_images(const DeviceLightmap& lightmap, const TexelGBuffer& gbuffer,
                                                            int dilation_texels) {
  if (!impl_->page_images || !impl_->page_images->fits(gbuffer, dilation_texels)) {
    impl_->page_images.reset();
    impl_->page_images = std::make_unique<LightmapPageImages>(impl_->context, gbuffer, dilation_texels);
  }
  return impl_->page_images->write(lightmap);
}

std::shared_ptr<DeviceLightmap> VulkanIntegrator::denoise_indirect(const DeviceLightmap& published, const TexelGBuffer& gbuffer,
                                                                  int radius, DeviceDenoiseCounts* counts, bool totals_only) {
  if (radius < 1 || radius > kFilterMaxRadius)
    throw std::invalid_argument("denoise_indirect: radius " + std::to_string(radius) + " is not 1 to " + std::to_string(kFilterMaxRadius));
  if (published.directional)
    throw std::invalid_argument("denoise_indirect: the estimate has L1 sums, which are not split into direct and indirect light");
  if (published.layers < 1)
    throw std::invalid_argument("denoise_indirect: the estimate records no direct light (layer 0) to keep apart from the indirect");
  if (published.texels != gbuffer.texels.size())
    throw std::invalid_argument("denoise_indirect: the estimate has " + std::to_string(published.texels) + " texels, the G-buffer " +
                                std::to_string(gbuffer.texels.size()));
  if (!impl_->denoiser || impl_->denoiser_stale || !impl_->denoiser->fits(gbuffer)) {
    impl_->denoiser.reset();
    impl_->denoiser = std::make_unique<IndirectDenoiser>(impl_->context, gbuffer);
    impl_->denoiser_stale = false;
  }
  std::shared_ptr<DeviceLightmap>& out = impl_->denoised;
  if (!out || out.use_count() > 1 || out->texels != published.texels || out->layers != published.layers)
    out = std::make_shared<DeviceLightmap>(impl_->context, published.texels, published.layers, false, 0);
  const DeviceDenoiseCounts filtered = impl_->denoiser->filter(published, *out, radius, totals_only);
  if (counts) *counts = filtered;
  return out;
}

std::vector<float> VulkanIntegrator::read_page_image(size_t page) const {
  if (!impl_->page_images) throw std::logic_error("VulkanIntegrator::read_page_image before write_page_images");
  return impl_->page_images->read_back(page);
}

VulkanExternalDevice VulkanIntegrator::vulkan_device() const {
  const Context& c = impl_->context;
  VulkanExternalDevice d;
  d.instance = c.instance();
  d.physical_device = c.physical_device();
  d.device = c.device();
  d.queue = c.queue();
  d.queue_family = c.queue_family();
  d.api_version = VK_API_VERSION_1_2;  // what the runtime's own instance asks for; an adopted one's is at least that
  d.enabled_features = c.enabled_features();
  d.timeline_semaphore = c.timeline_semaphores();
  return d;
}
uint32_t VulkanIntegrator::progressive_samples() const { return impl_->lightmap.samples_done(); }

void VulkanIntegrator::update_materials(const LightingScene& edited) {
  impl_->scene.update_materials(edited);
  impl_->lightmap.set_guiding_scene(guiding_scene(edited, impl_->created_on));
}
void VulkanIntegrator::update_lights(const LightingScene& edited) {
  impl_->scene.update_lights(edited);
  impl_->lightmap.set_guiding_scene(guiding_scene(edited, impl_->created_on));
}
void VulkanIntegrator::update_punctual_lights(const LightingScene& edited) {
  impl_->scene.update_punctual_lights(edited);
  impl_->lightmap.set_guiding_scene(guiding_scene(edited, impl_->created_on));
}
void VulkanIntegrator::update_moved_geometry(const LightingScene& edited, const Bvh4Links& links,
                                             const std::vector<uint32_t>& moved_triangles,
                                             const std::vector<uint32_t>& changed_nodes, bool emitters_changed,
                                             bool materials_changed) {
  impl_->scene.update_moved_geometry(edited, links, moved_triangles, changed_nodes, emitters_changed, materials_changed);
  impl_->lightmap.set_guiding_scene(guiding_scene(edited, impl_->created_on));
  impl_->source = edited.source;
}
void VulkanIntegrator::update_texels(const TexelGBuffer& gbuffer, const std::vector<uint32_t>& texels) {
  impl_->lightmap.update_texels(gbuffer, texels);
  if (impl_->denoiser && !impl_->denoiser_stale) impl_->denoiser->update_texels(gbuffer, texels);
}
void VulkanIntegrator::update_geometry(const LightingScene& edited) {
  impl_->scene.update_geometry(edited);
  impl_->lightmap.set_guiding_scene(guiding_scene(edited, impl_->created_on));
  impl_->source = edited.source;
}

const VulkanDeviceInfo& VulkanIntegrator::device() const { return impl_->context.info(); }
uint64_t VulkanIntegrator::waited_submissions() const { return impl_->context.waits().submissions; }
double VulkanIntegrator::wait_seconds() const { return impl_->context.waits().seconds; }
std::string VulkanIntegrator::device_description() const {
  return device().name + " (" + to_string(device().type) + (impl_->context.adopted() ? ", adopted" : "") + ")";
}
uint32_t VulkanIntegrator::max_paths() const { return impl_->sizes.paths; }
size_t VulkanIntegrator::path_state_bytes_per_path() const { return WavefrontBuffers::kBytesPerPath; }
size_t VulkanIntegrator::bvh_bytes() const { return impl_->scene.bvh_bytes(); }
uint32_t VulkanIntegrator::bvh_node_count() const { return impl_->scene.bvh_node_count(); }
const std::vector<VulkanStageStatistics>& VulkanIntegrator::stage_statistics() const { return impl_->statistics.all(); }
double VulkanIntegrator::measure_incoherent_traversal(uint32_t ray_count, int repetitions) const {
  return vulkan::measure_incoherent_traversal(impl_->runner, ray_count, repetitions);
}

}  // namespace exitance
