// The wavefront's state on the device as typed structure-of-arrays buffers and queues
// (shaders/include/bindings.glsl declares the same, at gpu_layout.h's binding numbers).
#pragma once
#include <cstddef>
#include <cstdint>

#include "exitance/common/gpu_layout.h"
#include "exitance/runtime/texel_gbuffer.h"
#include "vulkan_context.h"
#include "wavefront_kernels.h"

namespace exitance::vulkan {

// What every kernel reads (GpuParams, updated in place per batch) and the counters they count in
// (queue sizes, work items claimed, rays, statistics), read back after each submission.
struct WavefrontControl {
  Buffer params;
  Buffer counters;  // kCounterCount uints (gpu_layout.h)
  Buffer readback;  // host-visible copy of the counters

  explicit WavefrontControl(Context& context);
  const uint32_t* read_back() const { return static_cast<const uint32_t*>(readback.mapped()); }
  // A 64-bit statistic of the read-back (lo, hi word pair from `slot`).
  uint64_t read_back64(uint32_t slot) const { return uint64_t(read_back()[slot]) | (uint64_t(read_back()[slot + 1]) << 32); }
  void bind(DescriptorWrites& writes) const;
};

// Path state, one entry per path slot.
struct PathStateBuffers {
  Buffer work;           // work item of the batch, or kInvalid
  Buffer depth;          // vertices so far
  Buffer rng;            // PathSampler (path_sampler.h): four uints
  Buffer throughput;     // rgb, pdf of the ray; then P more: the directional state; then, with emitter
                         // guiding, 2P more: what a vertex's next-event samples learn (gpu_layout.h)
  Buffer ray_origin;
  Buffer ray_direction;
  Buffer hit;            // t, triangle bits, b1, b2
  Buffer shadow_rays;    // next-event shadow rays waiting for connect: room for kShadowRaysPerVertex, stride GpuParams::shadow_slots

  PathStateBuffers(Context& context, uint32_t paths);
  void bind(DescriptorWrites& writes) const;
  // The throughput buffer with emitter guiding's 2P entries (a new buffer when it grows: rebind),
  // and after them the light subpaths' P where both run (path.glsl eye_subpath_index). Returns
  // whether it grew.
  bool reserve_emitter_learning(Context& context, bool light_subpaths = false);
  // Light subpaths: the throughput buffer with the eye-vertex state's P entries (after emitter
  // guiding's 2P where `emitter_learning`), and with an environment map a fourth shadow slot per
  // path (gpu_layout.h kShadowSlotsWith*). New buffers when they grow (rebind); returns whether one did.
  bool reserve_light_subpaths(Context& context, bool environment, bool emitter_learning = false);
  uint32_t paths = 0;
  static constexpr size_t kBytesPerPath = 4 + 4 + 16 + 16 + 16 + 16 + 16 + kShadowRaysPerVertex * sizeof(ShadowRay);
};

// Paths whose continuation ray waits for extend, then shade: two queues of a slot per path,
// ping-pong (shade reads queue q and appends to q ^ 1, which extend reads); sizes in the counters
// kCounterRayQueue0 + q.
struct RayQueue {
  Buffer entries;

  RayQueue(Context& context, uint32_t paths);
  void bind(DescriptorWrites& writes) const;
  static constexpr size_t kBytesPerPath = 8;
};

// Paths whose shadow rays wait for connect; size in the counter kCounterShadowQueue.
struct ShadowQueue {
  Buffer entries;

  ShadowQueue(Context& context, uint32_t paths);
  void bind(DescriptorWrites& writes) const;
  static constexpr size_t kBytesPerPath = 4;
};

// A launch over a queue reads its grid size here: vkCmdDispatchIndirect arguments.
struct IndirectDispatch {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceSize offset = 0;
};

// The grid sizes prepare.comp writes from the queue sizes (three uints each).
struct QueueDispatches {
  Buffer arguments;

  explicit QueueDispatches(Context& context);
  IndirectDispatch shade() const { return {arguments.handle(), 0}; }     // ray queue q
  IndirectDispatch connect() const { return {arguments.handle(), 12}; }  // shadow queue
  IndirectDispatch extend() const { return {arguments.handle(), 24}; }   // ray queue q ^ 1
  void bind(DescriptorWrites& writes) const;
};

// A bake's items (texels or probes): their start points, and the list a batch takes its items
// from (batch_items[batch_item_offset + i]). Grown as bakes need, never shrunk.
// A live texel as the estimator's start point (WorkItems::start_points).
inline GpuSurfacePoint texel_start_point(const LiveTexel& t) {
  return {Vec4(t.position, 0.0f), Vec4(t.geometric_normal, 0.0f), Vec4(t.shading_normal, 0.0f)};
}

struct WorkItems {
  Buffer start_points;  // GpuSurfacePoint per item
  Buffer batch_items;   // item indices
  // Whose items the buffers hold, so a driver that keeps an accumulation between calls (the
  // lightmap's progressive one) knows when another bake overwrote them.
  enum class Owner { None, Texels, Probes } owner = Owner::None;

  explicit WorkItems(Context& context);
  void reserve(Context& context, size_t items);
  void bind(DescriptorWrites& writes) const;
};

// Result slots of a batch's work items: texels, E/pi per recorded bounce layer; probes, see
// bindings.glsl's result_index and probe_extra_index.
struct SampleResults {
  Buffer slots;

  explicit SampleResults(Context& context);
  void reserve(Context& context, VkDeviceSize bytes);
  void bind(DescriptorWrites& writes) const;
};

// Per texel, over the bake's samples: total and squared total (doubles), per bounce layer, counts.
struct TexelAccumulators {
  Buffer sums;         // [texel][total rgb, squared rgb], then for directional bakes [texel][axis][rgb] of L1
  Buffer bounce_sums;  // [layer][texel][rgb]
  Buffer samples;      // [texel]

  explicit TexelAccumulators(Context& context);
  void reserve(Context& context, size_t texels, int layers, bool directional = false);
  void clear(VkCommandBuffer cmd) const;
  void bind(DescriptorWrites& writes) const;
};

// Per probe, over the bake's samples: L2 SH sums (doubles) and counts.
struct ProbeAccumulators {
  // [probe][coefficient][rgb], then [probe][rgb] sums of squared L0 terms, then per light layer
  // [layer][probe][coefficient][rgb] (reduce_probes.comp; bindings.glsl acc_probe_sh)
  Buffer sh_sums;
  Buffer counts;   // [probe][samples, back-face hits]

  static constexpr size_t kSumsPerProbe = 30;  // 27 SH sums and 3 squared L0 sums
  static VkDeviceSize sum_bytes(size_t probes, int light_layers) { return VkDeviceSize(probes) * (kSumsPerProbe + 27 * size_t(light_layers)) * 8; }
  explicit ProbeAccumulators(Context& context);
  void reserve(Context& context, size_t probes, int light_layers = 0);
  // Per-bounce lightmap bakes keep their layer caches in sh_sums (gpu_layout.h kBindingBounceCache).
  void reserve_bytes(Context& context, VkDeviceSize sh_sum_bytes);
  void clear(VkCommandBuffer cmd) const;
  void bind(DescriptorWrites& writes) const;
};

// Everything of the wavefront but the scene.
// Light subpaths (gpu_layout.h kBindingLightSubpaths): the batch's pool, header, per-subpath offsets
// and vertices. A placeholder until a bake with light subpaths reserves it.
struct LightPool {
  Buffer words;

  explicit LightPool(Context& context);
  // Room for `vertices` pool vertices (a new buffer when it grows: rebind); returns whether it grew.
  bool reserve(Context& context, uint64_t vertices);
  // The most vertices the buffer holds (0: the placeholder).
  uint32_t capacity() const;
  void bind(DescriptorWrites& writes) const;
};

struct WavefrontBuffers {
  WavefrontControl control;
  PathStateBuffers paths;
  RayQueue rays;
  ShadowQueue shadows;
  QueueDispatches dispatches;
  WorkItems items;
  SampleResults results;
  TexelAccumulators texels;
  ProbeAccumulators probes;
  // The runtime's progressive probes (probe_refresh.h): their own items and sums, so that refreshing
  // them between lightmap passes neither uploads the texels' start points again nor touches a
  // whole-run probe bake's sums. Bound instead of `items` and `probes` while `probe_refresh_bound`.
  WorkItems refresh_probe_items;
  ProbeAccumulators refresh_probe_sums;
  bool probe_refresh_bound = false;
  LightPool light_pool;

  WavefrontBuffers(Context& context, uint32_t path_count);
  void bind(DescriptorWrites& writes) const;
  static constexpr size_t kBytesPerPath =
      PathStateBuffers::kBytesPerPath + RayQueue::kBytesPerPath + ShadowQueue::kBytesPerPath;
};

}  // namespace exitance::vulkan
