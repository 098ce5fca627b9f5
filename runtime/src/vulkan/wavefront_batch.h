// One batch of work items through the wavefront, shared by the lightmap and probe drivers. A batch
// is a slice of the bake's items times a range of sample indices, one work item (item, sample)
// each. Generate fills every path slot with work items in order; rounds of shade -> connect ->
// extend follow until no path continues (finished paths take the next work items, so the batch
// ends with a drain); reduce then adds the batch's samples to the per-item sums in sample order,
// the result of each work item having one writer, its path.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>

#include "exitance/runtime/core/integrator_settings.h"
#include "gpu_scene.h"
#include "kernel_launches.h"
#include "wavefront_buffers.h"
#include "wavefront_kernels.h"
#include "wavefront_sizes.h"

namespace exitance::vulkan {

// Launch names (the keys of the per-stage statistics).
namespace stage {
inline constexpr char kGenerateTexelPaths[] = "generate: texel paths into every path slot";
inline constexpr char kGenerateProbeRays[] = "generate: probe rays into every path slot";
inline constexpr char kPrepareShade[] = "prepare: shade grid from the ray queue";
inline constexpr char kShadeTexelPaths[] = "shade: hits, emission, next-event, continuation";
inline constexpr char kShadeProbeRays[] = "shade: probe ray hits, then the texel estimator";
inline constexpr char kPrepareTrace[] = "prepare: connect and extend grids from the queues";
inline constexpr char kConnect[] = "connect: shadow rays (any hit)";
inline constexpr char kExtend[] = "extend: continuation rays (closest hit)";
inline constexpr char kReduceTexels[] = "reduce: samples into texel sums";
inline constexpr char kReduceProbes[] = "reduce: samples onto probe SH sums";
inline constexpr char kTraversalOnly[] = "traversal only: incoherent rays (closest hit)";
inline constexpr char kLightSubpathsCount[] = "light subpaths: traced, their vertices counted";
inline constexpr char kLightSubpathsOffsets[] = "light subpaths: where each one's vertices start";
inline constexpr char kLightSubpathsWrite[] = "light subpaths: traced again, their vertices written";
inline constexpr char kRaysPrimary[] = "rays: primary";
inline constexpr char kRaysBounce[] = "rays: bounce";
}  // namespace stage

// The kernels that differ between texel and probe work items.
struct BatchKernels {
  Kernel generate;
  const char* generate_name;
  Kernel shade;
  const char* shade_name;
  Kernel reduce;
  const char* reduce_name;
};
inline constexpr BatchKernels kTexelBatch{Kernel::Generate, stage::kGenerateTexelPaths, Kernel::Shade,
                                          stage::kShadeTexelPaths, Kernel::ReduceTexels, stage::kReduceTexels};
inline constexpr BatchKernels kProbeBatch{Kernel::GenerateProbes, stage::kGenerateProbeRays, Kernel::ShadeProbes,
                                          stage::kShadeProbeRays, Kernel::ReduceProbes, stage::kReduceProbes};

// Items [offset, offset + count) of the bake's work list, samples [sample_begin, + samples).
struct BatchRange {
  uint32_t offset = 0, count = 0, sample_begin = 0, samples = 0;
};

// Sums of a bake's counter read-backs (gpu_layout.h's counter slots).
struct BatchTotals {
  uint64_t rays_primary = 0, rays_bounce = 0, rays_shadow = 0, nonfinite = 0;
  uint64_t bounce_gathers = 0, bounce_texelless = 0, bounce_back_faces = 0;  // per-bounce layer passes
  uint64_t guided_vertices = 0;  // guided batches: vertices that sampled a learned table
  // Light subpaths: the pools' subpaths and vertices (a pool left empty counts its subpaths as 0 and
  // the vertices it needed: pool_vertices_needed), and their rays (both traces).
  uint64_t light_subpaths = 0, light_subpath_vertices = 0, light_subpath_rays = 0;
  uint32_t pool_vertices_needed = 0;  // the largest a batch's pool needed
  uint64_t extend_busy = 0, extend_launched = 0, connect_busy = 0, connect_launched = 0, shade_items = 0, shade_lanes = 0;
  uint64_t rays() const { return rays_primary + rays_bounce + rays_shadow + light_subpath_rays; }
  void add(const uint32_t* counters);
  void add(const BatchTotals& other);
};

class WavefrontBatchRunner {
 public:
  WavefrontBatchRunner(Context& context, const GpuScene& scene, WavefrontKernels& kernels, WavefrontBuffers& buffers,
                       StageStatistics& statistics, WavefrontSizes sizes, bool collect_statistics);

  // Writes the descriptor set from the scene's and the wavefront's buffers; drivers call it after
  // growing a buffer, and before each bake (a scene update may have grown one).
  void bind_buffers();
  // Dispatches every kernel once with no work (after bind_buffers), each in its own submission
  // bounded by `timeout_seconds`: drivers that compile at the first dispatch compile here.
  void compile_kernels(double timeout_seconds, const std::function<void(double)>& progress);
  // A bake's parameters before its batches: scene, settings, `recorded` result layers per work
  // item beyond the first, the bake's item count (the stride of per-item sums).
  GpuParams bake_params(const IntegratorSettings& settings, uint32_t recorded, uint32_t item_count) const;
  // Work items per batch with `result_bytes` of result slots each: the paths' share, within the
  // device's largest storage buffer.
  size_t work_items_per_batch(size_t result_bytes) const;

  void run(GpuParams& params, BatchRange range, size_t result_bytes_per_item, const BatchKernels& kernels, BatchTotals& totals);
  // The counters' figures of a bake, under the names of the launches they measure.
  void record_statistics(const BatchTotals& totals, const BatchKernels& kernels);

  Context& context() { return context_; }
  const GpuScene& scene() const { return scene_; }
  WavefrontBuffers& buffers() { return buffers_; }
  StageStatistics& statistics() { return statistics_; }
  const WavefrontSizes& sizes() const { return sizes_; }
  KernelLaunches launches(bool timed);
  void update_params(KernelLaunches& launches, const GpuParams& params);
  void copy_counters(KernelLaunches& launches);

 private:
  void check_faults(const char* stage_name);  // throws VulkanDeviceFailure on a counted kernel fault
  void shade_queued_hits(KernelLaunches& launches, const BatchKernels& kernels, uint32_t queue);
  void trace_queued_rays(KernelLaunches& launches, uint32_t queue);

  Context& context_;
  const GpuScene& scene_;
  WavefrontKernels& kernels_;
  WavefrontBuffers& buffers_;
  StageStatistics& statistics_;
  WavefrontSizes sizes_;
  bool collect_statistics_;
};

}  // namespace exitance::vulkan
