#include "wavefront_batch.h"

#include <algorithm>
#include <cstddef>
#include <string>

namespace exitance::vulkan {
namespace {

static_assert(sizeof(GpuParams) == 272);  // a multiple of 16 bytes (std430 rounds a struct with vec4s so)
static_assert(offsetof(GpuParams, light_subpath_start) == 240);  // std430: a vec4 at a multiple of 16
static_assert(sizeof(GpuParams::changed_light_layers) / sizeof(uint32_t) == kMaxChangedLightPairs);
static_assert(sizeof(GpuSurfacePoint) == 48 && sizeof(ShadowRay) == 32);

uint64_t stat64(const uint32_t* c, uint32_t slot) { return uint64_t(c[slot]) | (uint64_t(c[slot + 1]) << 32); }

double ratio(uint64_t a, uint64_t b) { return b ? double(a) / double(b) : 0.0; }

}  // namespace

void BatchTotals::add(const uint32_t* c) {
  rays_primary += c[kCounterRaysPrimary], rays_bounce += c[kCounterRaysBounce], rays_shadow += c[kCounterRaysShadow];
  nonfinite += c[kCounterNonfinite];
  bounce_gathers += c[kCounterBounceGathers], bounce_texelless += c[kCounterBounceTexelless];
  bounce_back_faces += c[kCounterBounceBackFaces];
  guided_vertices += stat64(c, kCounterGuidedVertices);
  light_subpaths += c[kCounterLightSubpaths], light_subpath_rays += c[kCounterRaysLightSubpaths];
  if (c[kCounterLightSubpaths] > 0) light_subpath_vertices += c[kCounterLightSubpathVertices];
  pool_vertices_needed = std::max(pool_vertices_needed, c[kCounterLightSubpathVertices]);
  extend_busy += stat64(c, kCounterStatExtendActive), extend_launched += stat64(c, kCounterStatExtendLaunched);
  connect_busy += stat64(c, kCounterStatConnectActive), connect_launched += stat64(c, kCounterStatConnectLaunched);
  shade_items += stat64(c, kCounterStatShadeItems), shade_lanes += stat64(c, kCounterStatShadeLanes);
}

void BatchTotals::add(const BatchTotals& o) {
  rays_primary += o.rays_primary, rays_bounce += o.rays_bounce, rays_shadow += o.rays_shadow, nonfinite += o.nonfinite;
  bounce_gathers += o.bounce_gathers, bounce_texelless += o.bounce_texelless, bounce_back_faces += o.bounce_back_faces;
  guided_vertices += o.guided_vertices;
  light_subpaths += o.light_subpaths, light_subpath_vertices += o.light_subpath_vertices, light_subpath_rays += o.light_subpath_rays;
  pool_vertices_needed = std::max(pool_vertices_needed, o.pool_vertices_needed);
  extend_busy += o.extend_busy, extend_launched += o.extend_launched, connect_busy += o.connect_busy;
  connect_launched += o.connect_launched, shade_items += o.shade_items, shade_lanes += o.shade_lanes;
}

WavefrontBatchRunner::WavefrontBatchRunner(Context& context, const GpuScene& scene, WavefrontKernels& kernels,
                                           WavefrontBuffers& buffers, StageStatistics& statistics, WavefrontSizes sizes,
                                           bool collect_statistics)
    : context_(context),
      scene_(scene),
      kernels_(kernels),
      buffers_(buffers),
      statistics_(statistics),
      sizes_(sizes),
      collect_statistics_(collect_statistics) {}

void WavefrontBatchRunner::bind_buffers() {
  DescriptorWrites writes;
  scene_.bind(writes);
  buffers_.bind(writes);
  kernels_.write_descriptors(writes);
}

void WavefrontBatchRunner::compile_kernels(double timeout_seconds, const std::function<void(double)>& progress) {
  for (uint32_t k = 0; k < uint32_t(Kernel::Count); ++k) {
    if (progress) progress(double(k) / double(Kernel::Count));
    KernelLaunches launches(context_, kernels_, statistics_, false);
    update_params(launches, GpuParams{});  // no paths, items or work: every kernel returns at once
    vkCmdFillBuffer(launches.commands(), buffers_.control.counters.handle(), 0, VK_WHOLE_SIZE, 0);
    launches.barrier();
    launches.launch_to_compile(Kernel(k));
    launches.submit_and_wait(timeout_seconds);
  }
  if (progress) progress(1.0);
}

GpuParams WavefrontBatchRunner::bake_params(const IntegratorSettings& settings, uint32_t recorded, uint32_t item_count) const {
  GpuParams params{};
  params.sky = Vec4(scene_.sky(), 0.0f);
  params.scene_extent = scene_.extent();
  params.emitter_count = scene_.emitter_count();
  params.emitter_inverse_power = scene_.emitter_inverse_power();
  params.punctual_count = scene_.punctual_count();
  params.surface_flags = scene_.surface_flags();
  params.environment_width = scene_.environment_width();
  params.environment_height = scene_.environment_height();
  params.shadow_slots = scene_.environment_width() > 0 ? kShadowRaysPerVertex : kShadowSlotsWithoutEnvironment;
  params.recorded = recorded;
  params.max_bounces = settings.max_bounces;
  params.rr_start = settings.russian_roulette_start;
  params.safety_cap = settings.safety_bounce_cap;
  params.path_capacity = sizes_.paths;
  params.seed_lo = uint32_t(settings.seed), params.seed_hi = uint32_t(settings.seed >> 32);
  params.sampling_strategy = settings.sampling_strategy;
  params.sampler_mode = settings.sampler;
  params.collect_stats = collect_statistics_ ? 1u : 0u;
  params.item_count_total = item_count;
  params.traversal_steps = scene_.traversal_step_bound();
  return params;
}

size_t WavefrontBatchRunner::work_items_per_batch(size_t result_bytes) const {
  const size_t limit = size_t(context_.properties().limits.maxStorageBufferRange) / result_bytes;
  return std::max<size_t>(1, std::min<size_t>({size_t(sizes_.paths) * sizes_.work_items_per_path, limit, size_t(1) << 30}));
}

KernelLaunches WavefrontBatchRunner::launches(bool timed) { return KernelLaunches(context_, kernels_, statistics_, timed); }

void WavefrontBatchRunner::update_params(KernelLaunches& launches, const GpuParams& params) {
  vkCmdUpdateBuffer(launches.commands(), buffers_.control.params.handle(), 0, sizeof(params), &params);
  launches.barrier();
}

void WavefrontBatchRunner::copy_counters(KernelLaunches& launches) {
  const VkBufferCopy region{0, 0, kCounterCount * 4};
  vkCmdCopyBuffer(launches.commands(), buffers_.control.counters.handle(), buffers_.control.readback.handle(), 1, &region);
}

// Shade the hits of ray queue `queue`: continuations go to queue ^ 1, shadow rays to the shadow queue.
void WavefrontBatchRunner::shade_queued_hits(KernelLaunches& launches, const BatchKernels& kernels, uint32_t queue) {
  launches.launch(stage::kPrepareShade, Kernel::Prepare, 1, {queue, 0});
  launches.launch_queued(kernels.shade_name, kernels.shade, buffers_.dispatches.shade(), {queue, 0});
}

// Trace what shading queued: the shadow rays, and the continuation rays of queue ^ 1.
void WavefrontBatchRunner::trace_queued_rays(KernelLaunches& launches, uint32_t queue) {
  launches.launch(stage::kPrepareTrace, Kernel::Prepare, 1, {queue, 1});
  launches.launch_queued(stage::kConnect, Kernel::Connect, buffers_.dispatches.connect(), {queue, 0});
  launches.launch_queued(stage::kExtend, Kernel::Extend, buffers_.dispatches.extend(), {queue, 0});
}

void WavefrontBatchRunner::run(GpuParams& params, BatchRange range, size_t result_bytes_per_item,
                               const BatchKernels& kernels, BatchTotals& totals) {
  params.batch_item_offset = range.offset;
  params.batch_item_count = range.count;
  params.batch_sample_begin = range.sample_begin;
  params.batch_sample_count = range.samples;
  params.batch_work_total = range.count * range.samples;
  const bool timed = collect_statistics_;
  {
    KernelLaunches first = launches(timed);
    update_params(first, params);
    vkCmdFillBuffer(first.commands(), buffers_.control.counters.handle(), 0, VK_WHOLE_SIZE, 0);
    vkCmdFillBuffer(first.commands(), buffers_.results.slots.handle(), 0,
                    VkDeviceSize(params.batch_work_total) * result_bytes_per_item, 0);
    first.barrier();
    // Light subpaths: the batch's pool before its paths (light_subpaths.comp): counts, their offsets, vertices.
    if (params.light_subpaths > 0) {
      first.launch(stage::kLightSubpathsCount, Kernel::LightSubpaths, groups_for(params.light_subpaths), {0, kLightSubpathsCount});
      first.launch(stage::kLightSubpathsOffsets, Kernel::LightSubpaths, 1, {0, kLightSubpathsOffsets});
      first.launch(stage::kLightSubpathsWrite, Kernel::LightSubpaths, groups_for(params.light_subpaths), {0, kLightSubpathsWrite});
    }
    // Generate appends to ray queue 0, the queue the shade after it reads (push constant 1: "1 ^ 1").
    first.launch(kernels.generate_name, kernels.generate, groups_for(sizes_.paths), {1, 0});
    trace_queued_rays(first, 1);
    copy_counters(first);
    first.submit_and_wait();
  }
  check_faults(kernels.generate_name);
  // Progress watchdog: a path ends within its bounce cap (path.h safety_cap) plus its probe ray and
  // direct-light step, and every path that ends claims work, so the claim counter must move at least
  // once in that many iterations while rays are queued; if it does not, the wavefront is stuck.
  const uint64_t stall_limit = 2 * (uint64_t(std::max(params.safety_cap, 0)) + 4) + sizes_.iterations_per_submit;
  uint32_t claims = buffers_.control.read_back()[kCounterNextWork];
  uint64_t idle_iterations = 0;
  uint32_t queue = 0;
  while (buffers_.control.read_back()[kCounterRayQueue0 + queue] > 0) {
    KernelLaunches rounds = launches(timed);
    for (uint32_t i = 0; i < sizes_.iterations_per_submit; ++i, queue ^= 1u) {
      shade_queued_hits(rounds, kernels, queue);
      trace_queued_rays(rounds, queue);
    }
    copy_counters(rounds);
    rounds.submit_and_wait();
    check_faults(kernels.shade_name);
    const uint32_t now = buffers_.control.read_back()[kCounterNextWork];
    idle_iterations = now != claims ? 0 : idle_iterations + sizes_.iterations_per_submit;
    claims = now;
    if (idle_iterations > stall_limit)
      context_.fail(std::string("Vulkan wavefront stopped making progress in \"") + kernels.shade_name + "\": no path finished in " +
                    std::to_string(idle_iterations) + " iterations (the bounce cap allows " + std::to_string(stall_limit) + ")");
  }
  KernelLaunches reduce = launches(timed);
  // Probe batches reduce one thread per probe and slot: its totals, then each light layer (reduce_probes.comp).
  const uint32_t reduce_threads = kernels.reduce == Kernel::ReduceProbes ? range.count * (1 + params.light_layers) : range.count;
  reduce.launch(kernels.reduce_name, kernels.reduce, groups_for(reduce_threads));
  copy_counters(reduce);
  reduce.submit_and_wait();
  check_faults(kernels.reduce_name);
  totals.add(buffers_.control.read_back());
}

// Faults the kernels counted (gpu_layout.h) end the bake: they mean a broken invariant, whose
// results cannot be trusted, and the message names the stage that met it.
void WavefrontBatchRunner::check_faults(const char* stage_name) {
  const uint32_t* c = buffers_.control.read_back();
  if (c[kCounterFaultTraversal] > 0)
    context_.fail("Vulkan kernels: " + std::to_string(c[kCounterFaultTraversal]) + " BVH traversals exceeded the BVH's " +
                  "stack or step bound (corrupt nodes?) by the end of \"" + stage_name + "\"");
  if (c[kCounterFaultWorkClaim] > 0)
    context_.fail("Vulkan kernels: " + std::to_string(c[kCounterFaultWorkClaim]) +
                  " work claims did not advance the work counter by the end of \"" + stage_name + "\"");
}

void WavefrontBatchRunner::record_statistics(const BatchTotals& t, const BatchKernels& kernels) {
  VulkanStageStatistics& extend = statistics_[stage::kExtend];
  extend.rays = extend.items = t.rays_primary + t.rays_bounce;
  extend.lane_efficiency = ratio(t.extend_busy, t.extend_launched);
  VulkanStageStatistics& connect = statistics_[stage::kConnect];
  connect.rays = t.rays_shadow;
  connect.lane_efficiency = ratio(t.connect_busy, t.connect_launched);
  VulkanStageStatistics& shade = statistics_[kernels.shade_name];
  shade.items = t.shade_items;
  shade.lane_efficiency = ratio(t.shade_items, t.shade_lanes);
  statistics_[stage::kRaysPrimary] = {stage::kRaysPrimary, 0, t.rays_primary, t.rays_primary, 0};
  statistics_[stage::kRaysBounce] = {stage::kRaysBounce, 0, t.rays_bounce, t.rays_bounce, 0};
}

}  // namespace exitance::vulkan
