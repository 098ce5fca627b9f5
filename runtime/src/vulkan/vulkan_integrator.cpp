// Host side of the wavefront path tracer (shaders/wavefront/*.comp). One bake is a sequence of
// batches; a batch is a set of work items (texel, sample) = a slice of the live texel list times a
// range of sample indices. Path slots pull work items in order (generate, and regeneration inside
// shade) until the batch is exhausted, then drain (the cool-down), so every texel gets exactly the
// samples of the batch. Each work item owns a result slot (one writer), and the reduce kernel adds
// the batch's samples to per-texel double sums in sample order.
// Light probes (bake_probes) run through the same kernels as work items (probe, sample) of probe
// batches, in variants of generate and shade specialised for probes (kProbeMode, so the lightmap
// kernels compile without the probe code): regenerate emits the probe's stratified sphere ray, shade
// weighs what it meets as the reference's radiance_along_ray does and continues into the texel
// estimator at the hit, and reduce_probes projects each sample onto L2 SH into per-probe double sums.
#include "exitance/runtime/vulkan/vulkan_integrator.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "exitance/common/gpu_layout.h"
#include "exitance/runtime/core/scene_access.h"
#include "exitance/runtime/core/pass_scheduler.h"
#include "exitance_spirv/bench_rays.h"
#include "exitance_spirv/connect.h"
#include "exitance_spirv/extend.h"
#include "exitance_spirv/generate.h"
#include "exitance_spirv/prepare.h"
#include "exitance_spirv/reduce.h"
#include "exitance_spirv/reduce_probes.h"
#include "exitance_spirv/shade.h"
#include "bvh_quantization.h"
#include "vulkan_context.h"

namespace exitance {
using namespace exitance::vulkan;

namespace {

static_assert(sizeof(GpuParams) == 128);
static_assert(sizeof(GpuTriangle) == 96 && sizeof(GpuMaterial) == 32 && sizeof(GpuPunctualLight) == 48);
static_assert(sizeof(GpuSurfacePoint) == 48 && sizeof(ShadowRay) == 32);

// Pipelines. The first kStageCount are the stages of the statistics; the probe variants of generate
// and shade (specialization constant 2 set) count as those stages.
enum Kernel {
  kGenerate, kShade, kExtend, kConnect, kPrepare, kReduce, kBenchRays, kReduceProbes, kGenerateProbes, kShadeProbes,
  kKernelCount
};
constexpr int kStageCount = kGenerateProbes;
const char* const kKernelNames[kKernelCount] = {"generate", "shade",          "extend",        "connect",
                                                "prepare",  "reduce",         "traversal-only", "reduce probes",
                                                "generate (probes)", "shade (probes)"};
int stage_of(int kernel) { return kernel == kGenerateProbes ? kGenerate : kernel == kShadeProbes ? kShade : kernel; }

constexpr uint32_t kGroupSize = 64;
constexpr int kMaxRecordedBounces = 16;

struct PushConstants {
  uint32_t cur;
  uint32_t mode;
};

uint64_t stat64(const uint32_t* c, uint32_t slot) { return uint64_t(c[slot]) | (uint64_t(c[slot + 1]) << 32); }

}  // namespace

struct VulkanIntegrator::Impl {
  std::shared_ptr<const LightingScene> lighting;
  const LightingScene& scene;
  VulkanDeviceOptions options;
  std::unique_ptr<Context> ctx;
  uint32_t paths = 0;
  uint32_t iterations_per_submit = 8;
  uint32_t work_per_path = 4;
  // Node layout: quantized 64-byte nodes pay on CPU devices (lavapipe: fewer gathered words per
  // node), float 112-byte nodes on GPUs (the H100 traversal is bound by instructions, not by node
  // bytes: the BVH stays in L2). Measured: bench/results/vulkan-{lavapipe,gpu}.md.
  bool quantized_nodes = false;

  std::array<Buffer, kBindingCount> buffers{};
  Buffer readback;  // counters after each submission
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout pipeline_layout = VK_NULL_HANDLE;
  VkDescriptorPool descriptor_pool = VK_NULL_HANDLE;
  VkDescriptorSet descriptor_set = VK_NULL_HANDLE;
  std::array<VkPipeline, kKernelCount> pipelines{};
  VkQueryPool query_pool = VK_NULL_HANDLE;
  static constexpr uint32_t kMaxQueries = 1024;

  // Per-bake buffer capacities (re-created when a bake needs more).
  size_t texel_capacity = 0, result_capacity = 0, bounce_layers = 0;
  mutable std::vector<VulkanStageStatistics> stats;

  Impl(std::shared_ptr<const LightingScene> s, const VulkanDeviceOptions& o) : lighting(std::move(s)), scene(*lighting), options(o) {}

  ~Impl() {
    if (!ctx) return;
    VkDevice d = ctx->device();
    if (!ctx->lost()) vkDeviceWaitIdle(d);
    for (VkPipeline p : pipelines)
      if (p) vkDestroyPipeline(d, p, nullptr);
    if (query_pool) vkDestroyQueryPool(d, query_pool, nullptr);
    if (descriptor_pool) vkDestroyDescriptorPool(d, descriptor_pool, nullptr);
    if (pipeline_layout) vkDestroyPipelineLayout(d, pipeline_layout, nullptr);
    if (set_layout) vkDestroyDescriptorSetLayout(d, set_layout, nullptr);
    for (Buffer& b : buffers) ctx->destroy(b);
    ctx->destroy(readback);
  }

  Buffer& buf(uint32_t b) { return buffers[b]; }

  void make_buffer(uint32_t b, VkDeviceSize size, VkBufferUsageFlags extra = 0) {
    ctx->destroy(buffers[b]);
    const VkDeviceSize limit = ctx->properties().limits.maxStorageBufferRange;
    if (size > limit)
      throw std::runtime_error("Vulkan backend: a buffer of " + std::to_string(size) + " bytes exceeds this device's " +
                               "maxStorageBufferRange (" + std::to_string(limit) + "); use fewer paths or texels per bake");
    buffers[b] = ctx->create_buffer(size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | extra, false);
  }

  template <typename T>
  void make_and_upload(uint32_t b, const std::vector<T>& data) {
    make_buffer(b, data.size() * sizeof(T));
    ctx->upload(buffers[b], data.data(), data.size() * sizeof(T));
  }

  void write_descriptors() {
    std::array<VkDescriptorBufferInfo, kBindingCount> infos{};
    std::array<VkWriteDescriptorSet, kBindingCount> writes{};
    for (uint32_t i = 0; i < kBindingCount; ++i) {
      infos[i] = {buffers[i].buffer, 0, VK_WHOLE_SIZE};
      writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      writes[i].dstSet = descriptor_set;
      writes[i].dstBinding = i;
      writes[i].descriptorCount = 1;
      writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      writes[i].pBufferInfo = &infos[i];
    }
    vkUpdateDescriptorSets(ctx->device(), kBindingCount, writes.data(), 0, nullptr);
  }

  void create_pipelines() {
    VkDevice d = ctx->device();
    std::array<VkDescriptorSetLayoutBinding, kBindingCount> bindings{};
    for (uint32_t i = 0; i < kBindingCount; ++i)
      bindings[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
    VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    set_info.bindingCount = kBindingCount;
    set_info.pBindings = bindings.data();
    check(vkCreateDescriptorSetLayout(d, &set_info, nullptr, &set_layout), "vkCreateDescriptorSetLayout");
    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(PushConstants)};
    VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layout_info.setLayoutCount = 1;
    layout_info.pSetLayouts = &set_layout;
    layout_info.pushConstantRangeCount = 1;
    layout_info.pPushConstantRanges = &range;
    check(vkCreatePipelineLayout(d, &layout_info, nullptr, &pipeline_layout), "vkCreatePipelineLayout");
    VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kBindingCount};
    VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pool_info.maxSets = 1;
    pool_info.poolSizeCount = 1;
    pool_info.pPoolSizes = &pool_size;
    check(vkCreateDescriptorPool(d, &pool_info, nullptr, &descriptor_pool), "vkCreateDescriptorPool");
    VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    alloc.descriptorPool = descriptor_pool;
    alloc.descriptorSetCount = 1;
    alloc.pSetLayouts = &set_layout;
    check(vkAllocateDescriptorSets(d, &alloc, &descriptor_set), "vkAllocateDescriptorSets");

    const std::array<std::pair<const uint32_t*, size_t>, kKernelCount> code = {{
        {spirv_generate, sizeof(spirv_generate)}, {spirv_shade, sizeof(spirv_shade)},
        {spirv_extend, sizeof(spirv_extend)}, {spirv_connect, sizeof(spirv_connect)},
        {spirv_prepare, sizeof(spirv_prepare)}, {spirv_reduce, sizeof(spirv_reduce)},
        {spirv_bench_rays, sizeof(spirv_bench_rays)}, {spirv_reduce_probes, sizeof(spirv_reduce_probes)},
        {spirv_generate, sizeof(spirv_generate)}, {spirv_shade, sizeof(spirv_shade)}}};
    // Specialization: 0 = traversal stack bound, 1 = node layout (quantized or float; bvh.glsl),
    // 2 = probe work items (bindings.glsl kProbeMode).
    const uint32_t stack_bound = std::max<uint32_t>(scene.bvh.stack_entries + 1, 8);
    const VkSpecializationMapEntry entries[3] = {
        {0, 0, sizeof(uint32_t)}, {1, sizeof(uint32_t), sizeof(uint32_t)}, {2, 2 * sizeof(uint32_t), sizeof(VkBool32)}};
    for (int k = 0; k < kKernelCount; ++k) {
      const uint32_t spec_values[3] = {stack_bound, quantized_nodes ? 1u : 0u,
                                       (k == kGenerateProbes || k == kShadeProbes) ? 1u : 0u};
      const VkSpecializationInfo spec{3, entries, sizeof(spec_values), spec_values};
      VkShaderModuleCreateInfo module_info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
      module_info.codeSize = code[size_t(k)].second;
      module_info.pCode = code[size_t(k)].first;
      VkShaderModule module;
      check(vkCreateShaderModule(d, &module_info, nullptr, &module), "vkCreateShaderModule");
      VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
      info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
      info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
      info.stage.module = module;
      info.stage.pName = "main";
      info.stage.pSpecializationInfo = &spec;
      info.layout = pipeline_layout;
      const VkResult r = vkCreateComputePipelines(d, VK_NULL_HANDLE, 1, &info, nullptr, &pipelines[size_t(k)]);
      vkDestroyShaderModule(d, module, nullptr);
      check(r, (std::string("creating the ") + kKernelNames[k] + " pipeline").c_str());
    }
    if (ctx->timestamps()) {
      VkQueryPoolCreateInfo q{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
      q.queryType = VK_QUERY_TYPE_TIMESTAMP;
      q.queryCount = kMaxQueries;
      check(vkCreateQueryPool(d, &q, nullptr, &query_pool), "vkCreateQueryPool");
    }
  }

  // Scene upload: the LightingScene's records as they are (gpu_layout.h), the BVH in the chosen
  // node layout, and per leaf slot a copy of its triangle's vertices for traversal.
  void upload_scene() {
    if (quantized_nodes) {
      make_and_upload(kBindingBvhNodes, quantize_bvh4_nodes(scene.bvh.nodes));
    } else {
      std::vector<uint32_t> nodes(scene.bvh.nodes.size() * 28);
      std::memcpy(nodes.data(), scene.bvh.nodes.data(), nodes.size() * 4);
      make_and_upload(kBindingBvhNodes, nodes);
    }
    std::vector<Vec4> leaf(std::max<size_t>(scene.bvh.leaf_triangles.size(), 1) * 3);
    for (size_t slot = 0; slot < scene.bvh.leaf_triangles.size(); ++slot) {
      const uint32_t t = scene.bvh.leaf_triangles[slot];
      leaf[slot * 3] = Vec4(scene_triangle_vertex(scene, t, 0), std::bit_cast<float>(t));
      leaf[slot * 3 + 1] = Vec4(scene_triangle_vertex(scene, t, 1), 0.0f);
      leaf[slot * 3 + 2] = Vec4(scene_triangle_vertex(scene, t, 2), 0.0f);
    }
    make_and_upload(kBindingBvhTriangles, leaf);
    make_and_upload(kBindingTriangles, at_least_one(scene.triangles));
    make_and_upload(kBindingMaterials, at_least_one(scene.materials));
    make_and_upload(kBindingEmitterCdf, scene.emitter_cdf);
    make_and_upload(kBindingEmitterTriangles, at_least_one(scene.emitter_triangles));
    make_and_upload(kBindingPunctualLights, at_least_one(scene.punctual_lights));
    make_and_upload(kBindingPunctualCdf, scene.punctual_cdf);
  }

  // Vulkan buffers cannot be empty.
  template <typename T>
  static std::vector<T> at_least_one(const std::vector<T>& v) {
    return v.empty() ? std::vector<T>(1) : v;
  }

  void allocate_path_state() {
    make_buffer(kBindingParams, sizeof(GpuParams));
    make_buffer(kBindingCounters, kCounterCount * 4);
    make_buffer(kBindingIndirect, 16 * 4, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
    make_buffer(kBindingPathWork, size_t(paths) * 4);
    make_buffer(kBindingPathDepth, size_t(paths) * 4);
    make_buffer(kBindingPathRng, size_t(paths) * 16);
    make_buffer(kBindingPathThroughput, size_t(paths) * 16);
    make_buffer(kBindingPathRayOrigin, size_t(paths) * 16);
    make_buffer(kBindingPathRayDirection, size_t(paths) * 16);
    make_buffer(kBindingPathHit, size_t(paths) * 16);
    make_buffer(kBindingShadowRays, size_t(paths) * kShadowSlotsPerPath * sizeof(ShadowRay));
    make_buffer(kBindingRayQueue, size_t(paths) * 8);
    make_buffer(kBindingShadowQueue, size_t(paths) * 4);
    readback = ctx->create_buffer(kCounterCount * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
    for (uint32_t b : {kBindingStartPoints, kBindingBatchItems, kBindingResults, kBindingTexelSums, kBindingBounceSums, kBindingTexelSamples, kBindingProbeShSums, kBindingProbeCounts})
      make_buffer(b, 16);
  }

  size_t path_bytes() const { return 4 + 4 + 16 + 16 + 16 + 16 + 16 + kShadowSlotsPerPath * sizeof(ShadowRay) + 8 + 4; }

  // ---- command recording ----
  void barrier(VkCommandBuffer cmd) const {
    VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT |
                      VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT |
                             VK_PIPELINE_STAGE_TRANSFER_BIT,
                         0, 1, &b, 0, nullptr, 0, nullptr);
  }

  struct Recorder {
    const Impl& impl;
    VkCommandBuffer cmd;
    bool timing;
    uint32_t queries = 0;
    std::vector<int> query_kernel;  // stage that ended at query i (i >= 1)
    bool probes = false;            // probe batch: the probe variants of generate and shade

    void start() {
      vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, impl.pipeline_layout, 0, 1, &impl.descriptor_set, 0, nullptr);
      if (timing) {
        vkCmdResetQueryPool(cmd, impl.query_pool, 0, kMaxQueries);
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, impl.query_pool, queries++);
        query_kernel.push_back(-1);
      }
    }
    void stamp(int kernel) {
      if (!timing || queries >= kMaxQueries) return;
      vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, impl.query_pool, queries++);
      query_kernel.push_back(stage_of(kernel));
    }
    void bind(Kernel k, uint32_t cur, uint32_t mode) {
      vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, impl.pipelines[k]);
      PushConstants pc{cur, mode};
      vkCmdPushConstants(cmd, impl.pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(pc), &pc);
    }
    void dispatch(Kernel k, uint32_t groups, uint32_t cur, uint32_t mode = 0) {
      bind(k, cur, mode);
      vkCmdDispatch(cmd, groups, 1, 1);
      impl.barrier(cmd);
      stamp(k);
    }
    void dispatch_indirect(Kernel k, uint32_t slot, uint32_t cur) {
      bind(k, cur, 0);
      vkCmdDispatchIndirect(cmd, impl.buffers[kBindingIndirect].buffer, VkDeviceSize(slot) * 12);
      impl.barrier(cmd);
      stamp(k);
    }
    // prepare(1) -> connect -> extend over the ray queue `cur ^ 1`.
    void connect_and_extend(uint32_t cur) {
      dispatch(kPrepare, 1, cur, 1);
      dispatch_indirect(kConnect, 1, cur);
      dispatch_indirect(kExtend, 2, cur);
    }
    // One wavefront iteration reading ray queue `cur`.
    void iteration(uint32_t cur) {
      dispatch(kPrepare, 1, cur, 0);
      dispatch_indirect(probes ? kShadeProbes : kShade, 0, cur);
      connect_and_extend(cur);
    }
    void copy_counters() {
      VkBufferCopy region{0, 0, kCounterCount * 4};
      vkCmdCopyBuffer(cmd, impl.buffers[kBindingCounters].buffer, impl.readback.buffer, 1, &region);
    }
  };

  void finish(Recorder& r) {
    ctx->submit_and_wait(r.cmd);
    if (!r.timing || r.queries < 2) return;
    std::vector<uint64_t> ts(r.queries);
    check(vkGetQueryPoolResults(ctx->device(), query_pool, 0, r.queries, ts.size() * 8, ts.data(), 8,
                                VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "vkGetQueryPoolResults");
    const double period = double(ctx->properties().limits.timestampPeriod) * 1e-9;
    for (uint32_t i = 1; i < r.queries; ++i) {
      const int k = r.query_kernel[i];
      if (k < 0) continue;
      stats[size_t(k)].seconds += double(ts[i] - ts[i - 1]) * period;
    }
  }

  const uint32_t* counters() const { return static_cast<const uint32_t*>(readback.mapped); }

  void set_params(VkCommandBuffer cmd, const GpuParams& p) {
    vkCmdUpdateBuffer(cmd, buffers[kBindingParams].buffer, 0, sizeof(p), &p);
    barrier(cmd);
  }

  void ensure_bake_buffers(size_t texel_count, int recorded, size_t max_work) {
    const size_t result_floats = max_work * size_t(recorded + 1) * 3;
    if (texel_count > texel_capacity || size_t(recorded) != bounce_layers) {
      make_buffer(kBindingStartPoints, texel_count * 48);
      make_buffer(kBindingBatchItems, texel_count * 4);
      make_buffer(kBindingTexelSums, texel_count * 6 * 8);
      make_buffer(kBindingBounceSums, size_t(recorded) * texel_count * 3 * 8);
      make_buffer(kBindingTexelSamples, texel_count * 4);
      texel_capacity = texel_count;
      bounce_layers = size_t(recorded);
    }
    if (result_floats > result_capacity) {
      make_buffer(kBindingResults, result_floats * 4);
      result_capacity = result_floats;
    }
    write_descriptors();
  }

  void reset_stats() const {
    stats.assign(kStageCount, {});
    for (int k = 0; k < kStageCount; ++k) stats[size_t(k)].stage = kKernelNames[k];
  }

  // Sums of a bake's counter read-backs.
  struct BatchTotals {
    uint64_t rays_primary = 0, rays_bounce = 0, rays_shadow = 0, nonfinite = 0;
    uint64_t extend_busy = 0, extend_launched = 0, connect_busy = 0, connect_launched = 0, shade_items = 0, shade_lanes = 0;
    uint64_t rays() const { return rays_primary + rays_bounce + rays_shadow; }
  };
  void run_wavefront_batch(const GpuParams& params, VkDeviceSize result_bytes, bool probes, bool timing,
                           BatchTotals& totals);
  void record_stats(const BatchTotals& totals) const;

  LightmapEstimate bake(const TexelGBuffer& gbuffer, const IntegratorSettings& settings);
  ProbeEstimate bake_probes(const std::vector<Vec3>& positions, const IntegratorSettings& settings);
  double traversal_bench(uint32_t ray_count, int repetitions);
};

LightmapEstimate VulkanIntegrator::Impl::bake(const TexelGBuffer& gbuffer, const IntegratorSettings& settings) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const size_t texel_count = gbuffer.texels.size();
  LightmapEstimate estimate;
  estimate.recorded_bounces = std::clamp(settings.recorded_bounces, 1, kMaxRecordedBounces);
  const int K = estimate.recorded_bounces;
  estimate.texels.resize(texel_count);
  estimate.bounces.assign(size_t(K) * texel_count * 3, 0.0);
  reset_stats();
  if (texel_count == 0) return estimate;
  if (texel_count >= (1ull << 31)) throw std::runtime_error("Vulkan backend: too many texels");

  // Work items per batch: enough to keep every path slot busy between drains, bounded by memory.
  const size_t limit_items = size_t(ctx->properties().limits.maxStorageBufferRange) / (size_t(K + 1) * 12);
  const size_t max_work = std::max<size_t>(1, std::min<size_t>({size_t(paths) * work_per_path, limit_items, size_t(1) << 30}));
  ensure_bake_buffers(texel_count, K, max_work);

  std::vector<GpuSurfacePoint> texels(texel_count);
  for (size_t i = 0; i < texel_count; ++i) {
    const LiveTexel& t = gbuffer.texels[i];
    texels[i] = {Vec4(t.position, 0.0f), Vec4(t.geometric_normal, 0.0f), Vec4(t.shading_normal, 0.0f)};
  }
  ctx->upload(buffers[kBindingStartPoints], texels.data(), texels.size() * sizeof(GpuSurfacePoint));
  std::vector<uint32_t> active(texel_count);
  for (size_t i = 0; i < texel_count; ++i) active[i] = uint32_t(i);
  ctx->upload(buffers[kBindingBatchItems], active.data(), active.size() * 4);
  {
    VkCommandBuffer cmd = ctx->begin();
    for (uint32_t b : {kBindingTexelSums, kBindingBounceSums, kBindingTexelSamples}) vkCmdFillBuffer(cmd, buffers[b].buffer, 0, VK_WHOLE_SIZE, 0);
    ctx->submit_and_wait(cmd);
  }

  GpuParams params{};
  params.sky = Vec4(scene.sky, 0.0f);
  params.scene_extent = scene.extent;
  params.emitter_count = scene.emitter_count();
  params.punctual_count = scene.punctual_count();
  params.recorded = uint32_t(K);
  params.max_bounces = settings.max_bounces;
  params.rr_start = settings.russian_roulette_start;
  params.safety_cap = settings.safety_bounce_cap;
  params.path_capacity = paths;
  params.seed_lo = uint32_t(settings.seed), params.seed_hi = uint32_t(settings.seed >> 32);
  params.sampling_strategy = settings.sampling_strategy;
  params.collect_stats = options.collect_stage_statistics ? 1u : 0u;
  params.item_count_total = uint32_t(texel_count);

  const bool timing = options.collect_stage_statistics && query_pool != VK_NULL_HANDLE;
  BatchTotals totals;

  auto run_batch = [&](uint32_t offset, uint32_t n, uint32_t sample_begin, uint32_t samples) {
    params.batch_item_offset = offset;
    params.batch_item_count = n;
    params.batch_sample_begin = sample_begin;
    params.batch_sample_count = samples;
    params.batch_work_total = n * samples;
    run_wavefront_batch(params, VkDeviceSize(n) * samples * uint32_t(K + 1) * 12, false, timing, totals);
  };

  const uint32_t spp_limit = settings.spp == 0 ? std::numeric_limits<uint32_t>::max() : settings.spp;
  PassPolicy policy;
  // Untimed: as many samples per batch as fill the work items; a budget or target error: ramped passes.
  policy.largest_pass = uint32_t(std::max<size_t>(1, max_work / std::min(texel_count, max_work)));
  policy.ramp = settings.time_budget_seconds > 0 || settings.target_relative_error > 0;
  PassScheduler passes(settings, policy);
  uint32_t first = 0, pass = 0;
  while (!active.empty() && passes.next_pass(first, pass)) {
    const size_t n_active = active.size();
    const uint32_t chunk = uint32_t(std::min(n_active, max_work));
    pass = std::min<uint32_t>(pass, uint32_t(std::max<size_t>(1, max_work / chunk)));
    for (size_t offset = 0; offset < n_active; offset += chunk) {
      const uint32_t n = uint32_t(std::min<size_t>(chunk, n_active - offset));
      run_batch(uint32_t(offset), n, first, pass);
    }
    const uint32_t done = first + pass;
    if (settings.target_relative_error > 0 && done >= 16 && done < spp_limit) {
      // Drop converged texels from the work list (the reference's test, estimates.h).
      std::vector<double> sums(texel_count * 6);
      std::vector<uint32_t> samples(texel_count);
      ctx->download(buffers[kBindingTexelSums], sums.data(), sums.size() * 8);
      ctx->download(buffers[kBindingTexelSamples], samples.data(), samples.size() * 4);
      std::vector<uint32_t> still;
      for (uint32_t i : active) {
        LightmapEstimate one;
        one.texels.resize(1);
        for (int c = 0; c < 3; ++c)
          one.texels[0].total[c] = sums[i * 6 + size_t(c)], one.texels[0].total_squared[c] = sums[i * 6 + 3 + size_t(c)];
        one.texels[0].samples = samples[i];
        if (!one.relative_error_below(0, settings.target_relative_error)) still.push_back(i);
      }
      if (still.size() != active.size()) {
        active = std::move(still);
        if (!active.empty()) ctx->upload(buffers[kBindingBatchItems], active.data(), active.size() * 4);
      }
    }
    passes.finish_pass(totals.rays(), active.empty());
  }

  std::vector<double> sums(texel_count * 6);
  std::vector<uint32_t> samples(texel_count);
  ctx->download(buffers[kBindingTexelSums], sums.data(), sums.size() * 8);
  ctx->download(buffers[kBindingTexelSamples], samples.data(), samples.size() * 4);
  ctx->download(buffers[kBindingBounceSums], estimate.bounces.data(), estimate.bounces.size() * 8);
  for (size_t i = 0; i < texel_count; ++i) {
    TexelAccumulator& a = estimate.texels[i];
    for (int c = 0; c < 3; ++c) {
      a.total[c] = sums[i * 6 + size_t(c)];
      a.total_squared[c] = sums[i * 6 + 3 + size_t(c)];
      a.direct[c] = estimate.bounces[i * 3 + size_t(c)];  // layer 0 is the direct light
    }
    a.samples = samples[i];
  }
  estimate.rays = totals.rays();
  estimate.nonfinite_samples = totals.nonfinite;
  estimate.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  record_stats(totals);
  return estimate;
}

// One batch: generate, wavefront iterations until every path slot is idle, then reduce over the
// batch's n texels (or probes). `result_bytes`: the part of the result buffer the batch writes.
void VulkanIntegrator::Impl::run_wavefront_batch(const GpuParams& params, VkDeviceSize result_bytes, bool probes,
                                                 bool timing, BatchTotals& totals) {
  const uint32_t n = params.batch_item_count;
  Recorder r{*this, ctx->begin(), timing};
  r.probes = probes;
  r.start();
  set_params(r.cmd, params);
  vkCmdFillBuffer(r.cmd, buffers[kBindingCounters].buffer, 0, VK_WHOLE_SIZE, 0);
  vkCmdFillBuffer(r.cmd, buffers[kBindingResults].buffer, 0, result_bytes, 0);
  barrier(r.cmd);
  r.dispatch(probes ? kGenerateProbes : kGenerate, (paths + kGroupSize - 1) / kGroupSize, 1);  // fills ray queue 0
  r.connect_and_extend(1);
  uint32_t cur = 0;
  r.copy_counters();
  finish(r);
  while (counters()[kCounterRayQueue0 + cur] > 0) {
    Recorder more{*this, ctx->begin(), timing};
    more.probes = probes;
    more.start();
    for (uint32_t i = 0; i < iterations_per_submit; ++i, cur ^= 1u) more.iteration(cur);
    more.copy_counters();
    finish(more);
  }
  Recorder reduce{*this, ctx->begin(), timing};
  reduce.start();
  reduce.dispatch(probes ? kReduceProbes : kReduce, (n + kGroupSize - 1) / kGroupSize, 0);
  reduce.copy_counters();
  finish(reduce);
  const uint32_t* c = counters();
  totals.rays_primary += c[kCounterRaysPrimary], totals.rays_bounce += c[kCounterRaysBounce], totals.rays_shadow += c[kCounterRaysShadow];
  totals.nonfinite += c[kCounterNonfinite];
  totals.extend_busy += stat64(c, kCounterStatExtendActive), totals.extend_launched += stat64(c, kCounterStatExtendLaunched);
  totals.connect_busy += stat64(c, kCounterStatConnectActive), totals.connect_launched += stat64(c, kCounterStatConnectLaunched);
  totals.shade_items += stat64(c, kCounterStatShadeItems), totals.shade_lanes += stat64(c, kCounterStatShadeLanes);
}

void VulkanIntegrator::Impl::record_stats(const BatchTotals& t) const {
  stats[kExtend].rays = stats[kExtend].items = t.rays_primary + t.rays_bounce;
  stats[kExtend].lane_efficiency = t.extend_launched ? double(t.extend_busy) / double(t.extend_launched) : 0.0;
  stats[kConnect].rays = t.rays_shadow;
  stats[kConnect].lane_efficiency = t.connect_launched ? double(t.connect_busy) / double(t.connect_launched) : 0.0;
  stats[kShade].items = t.shade_items;
  stats[kShade].lane_efficiency = t.shade_lanes ? double(t.shade_items) / double(t.shade_lanes) : 0.0;
  VulkanStageStatistics primary{"rays: primary", 0, t.rays_primary, t.rays_primary, 0};
  VulkanStageStatistics bounce{"rays: bounce", 0, t.rays_bounce, t.rays_bounce, 0};
  stats.push_back(primary);
  stats.push_back(bounce);
}

ProbeEstimate VulkanIntegrator::Impl::bake_probes(const std::vector<Vec3>& positions, const IntegratorSettings& settings) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const size_t probe_count = positions.size();
  ProbeEstimate estimate;
  estimate.sh_sum.assign(probe_count, std::array<double, 27>{});
  estimate.samples.assign(probe_count, 0);
  estimate.backface_hits.assign(probe_count, 0);
  reset_stats();
  if (probe_count == 0) return estimate;
  if (probe_count >= (1ull << 31)) throw std::runtime_error("Vulkan backend: too many probes");

  // Per work item: 2 result slots (12 bytes each), then albedo and direction (24 bytes).
  constexpr size_t kProbeItemBytes = 48;
  const size_t limit_items = size_t(ctx->properties().limits.maxStorageBufferRange) / kProbeItemBytes;
  const size_t max_work = std::max<size_t>(1, std::min<size_t>({size_t(paths) * work_per_path, limit_items, size_t(1) << 30}));
  const auto grow = [&](uint32_t b, size_t bytes) {
    if (buffers[b].size < bytes) make_buffer(b, bytes);
  };
  grow(kBindingStartPoints, probe_count * 48);
  grow(kBindingBatchItems, probe_count * 4);
  grow(kBindingProbeShSums, probe_count * 27 * 8);
  grow(kBindingProbeCounts, probe_count * 2 * 4);
  grow(kBindingResults, max_work * kProbeItemBytes);
  result_capacity = std::max<size_t>(result_capacity, buffers[kBindingResults].size / 4);
  write_descriptors();

  std::vector<GpuSurfacePoint> records(probe_count);  // start points with the position only
  for (size_t i = 0; i < probe_count; ++i) records[i].position = Vec4(positions[i], 0.0f);
  ctx->upload(buffers[kBindingStartPoints], records.data(), records.size() * sizeof(GpuSurfacePoint));
  std::vector<uint32_t> order(probe_count);
  for (size_t i = 0; i < probe_count; ++i) order[i] = uint32_t(i);
  ctx->upload(buffers[kBindingBatchItems], order.data(), order.size() * 4);
  {
    VkCommandBuffer cmd = ctx->begin();
    for (uint32_t b : {kBindingProbeShSums, kBindingProbeCounts}) vkCmdFillBuffer(cmd, buffers[b].buffer, 0, VK_WHOLE_SIZE, 0);
    ctx->submit_and_wait(cmd);
  }

  const uint32_t spp_limit = settings.spp == 0 ? std::numeric_limits<uint32_t>::max() : settings.spp;
  GpuParams params{};
  params.sky = Vec4(scene.sky, 0.0f);
  params.scene_extent = scene.extent;
  params.emitter_count = scene.emitter_count();
  params.punctual_count = scene.punctual_count();
  params.recorded = 1;  // slot 0: what the probe ray meets; slot 1: E/pi at its hit
  params.max_bounces = settings.max_bounces;
  params.rr_start = settings.russian_roulette_start;
  params.safety_cap = settings.safety_bounce_cap;
  params.path_capacity = paths;
  params.seed_lo = uint32_t(settings.seed), params.seed_hi = uint32_t(settings.seed >> 32);
  params.sampling_strategy = settings.sampling_strategy;
  params.collect_stats = options.collect_stage_statistics ? 1u : 0u;
  params.item_count_total = uint32_t(probe_count);
  params.probe_spp = spp_limit;

  const bool timing = options.collect_stage_statistics && query_pool != VK_NULL_HANDLE;
  BatchTotals totals;
  const uint32_t chunk = uint32_t(std::min(probe_count, max_work));
  PassPolicy policy;
  policy.largest_pass = uint32_t(std::max<size_t>(1, max_work / chunk));
  // With a time budget, passes end on stratified-set boundaries and the budget is only checked
  // there, so a stopped run never leaves a set's strata out (as the reference).
  policy.stratified_set = kProbeStratifiedSetSize;
  PassScheduler passes(settings, policy);
  uint32_t first = 0, pass = 0;
  while (passes.next_pass(first, pass)) {
    for (size_t offset = 0; offset < probe_count; offset += chunk) {
      const uint32_t n = uint32_t(std::min<size_t>(chunk, probe_count - offset));
      params.batch_item_offset = uint32_t(offset);
      params.batch_item_count = n;
      params.batch_sample_begin = first;
      params.batch_sample_count = pass;
      params.batch_work_total = n * pass;
      run_wavefront_batch(params, VkDeviceSize(n) * pass * kProbeItemBytes, true, timing, totals);
    }
    passes.finish_pass(totals.rays());
  }

  std::vector<double> sums(probe_count * 27);
  std::vector<uint32_t> counts(probe_count * 2);
  ctx->download(buffers[kBindingProbeShSums], sums.data(), sums.size() * 8);
  ctx->download(buffers[kBindingProbeCounts], counts.data(), counts.size() * 4);
  for (size_t i = 0; i < probe_count; ++i) {
    std::copy(sums.begin() + std::ptrdiff_t(i * 27), sums.begin() + std::ptrdiff_t(i * 27 + 27), estimate.sh_sum[i].begin());
    estimate.samples[i] = counts[i * 2];
    estimate.backface_hits[i] = counts[i * 2 + 1];
  }
  estimate.rays = totals.rays();
  estimate.nonfinite_samples = totals.nonfinite;
  estimate.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  record_stats(totals);
  return estimate;
}

double VulkanIntegrator::Impl::traversal_bench(uint32_t ray_count, int repetitions) {
  reset_stats();
  ensure_bake_buffers(std::max<size_t>(texel_capacity, 1), int(std::max<size_t>(bounce_layers, 1)), 1);
  GpuParams params{};
  params.path_capacity = paths;
  params.batch_work_total = ray_count;
  params.collect_stats = 1;
  params.seed_lo = 12345;
  params.bench_lo = Vec4(scene.bounds_lo, 0.0f);
  params.bench_hi = Vec4(scene.bounds_hi, 0.0f);
  if (!query_pool) throw std::runtime_error("Vulkan backend: this device has no timestamp queries");
  double best = 0;
  uint64_t busy = 0, launched = 0;
  for (int rep = 0; rep < std::max(1, repetitions); ++rep) {
    stats[kBenchRays].seconds = 0;
    Recorder r{*this, ctx->begin(), true};
    r.start();
    set_params(r.cmd, params);
    vkCmdFillBuffer(r.cmd, buffers[kBindingCounters].buffer, 0, VK_WHOLE_SIZE, 0);
    barrier(r.cmd);
    r.stamp(-1);
    r.dispatch(kBenchRays, (ray_count + kGroupSize - 1) / kGroupSize, 0);
    r.copy_counters();
    finish(r);
    const double seconds = stats[kBenchRays].seconds;
    if (seconds > 0) best = std::max(best, double(ray_count) / seconds);
    busy = stat64(counters(), kCounterStatExtendActive), launched = stat64(counters(), kCounterStatExtendLaunched);
  }
  stats[kBenchRays].rays = ray_count;
  stats[kBenchRays].items = counters()[kCounterRaysPrimary];  // rays that hit something
  stats[kBenchRays].seconds = double(ray_count) / std::max(best, 1e-30);
  stats[kBenchRays].lane_efficiency = launched ? double(busy) / double(launched) : 0.0;
  return best;
}

std::unique_ptr<VulkanIntegrator> VulkanIntegrator::create(std::shared_ptr<const LightingScene> scene,
                                                           const VulkanDeviceOptions& options) {
  if (!scene) throw std::invalid_argument("Vulkan backend: no scene");
  if (scene->environment.enabled())
    throw std::runtime_error("Vulkan backend: environment-map skies are not supported yet (use the cpu backend)");
  if (scene->textured)
    for (const Material& m : scene->source->materials)
      if (m.base_color_texture.texture >= 0 || m.emissive_texture.texture >= 0)
        throw std::runtime_error("Vulkan backend: textured materials are not supported yet (material '" + m.name +
                                 "'; use the cpu backend)");
  if (scene->bvh.nodes.empty()) throw std::invalid_argument("Vulkan backend: the scene has no BVH4 (build_bvh4 or scene.bin)");
  auto impl = std::make_unique<Impl>(std::move(scene), options);
  impl->ctx = std::make_unique<Context>(options);
  const bool cpu_device = impl->ctx->info().type == VulkanDeviceType::Cpu;
  // Paths in flight: on a GPU, more paths hide more latency and shorten the drains at batch ends
  // (H100, 1 M live texels: 1 Mi paths 1.46 s, 4 Mi paths 1.20 s; bench/results/vulkan-gpu.md);
  // 4 Mi paths take about 1.7 GB (path state + results), so only where the device has 16 GiB or more.
  VkDeviceSize device_local = 0;
  const VkPhysicalDeviceMemoryProperties& memory = impl->ctx->memory_properties();
  for (uint32_t h = 0; h < memory.memoryHeapCount; ++h)
    if (memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      device_local = std::max(device_local, memory.memoryHeaps[h].size);
  const uint32_t gpu_paths = device_local >= (VkDeviceSize(16) << 30) ? (1u << 22) : (1u << 20);
  impl->paths = options.max_paths ? options.max_paths : (cpu_device ? (1u << 14) : gpu_paths);
  impl->paths = std::max<uint32_t>(impl->paths, kGroupSize);
  impl->iterations_per_submit = options.iterations_per_submit ? options.iterations_per_submit : (cpu_device ? 8u : 32u);
  impl->quantized_nodes = options.node_layout == VulkanNodeLayout::Automatic ? cpu_device
                                                                            : options.node_layout == VulkanNodeLayout::Quantized;
  impl->work_per_path = options.work_items_per_path ? options.work_items_per_path : 4u;
  impl->upload_scene();
  impl->allocate_path_state();
  impl->create_pipelines();
  impl->write_descriptors();
  return std::unique_ptr<VulkanIntegrator>(new VulkanIntegrator(std::move(impl)));
}

VulkanIntegrator::VulkanIntegrator(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
VulkanIntegrator::~VulkanIntegrator() = default;

LightmapEstimate VulkanIntegrator::bake(const TexelGBuffer& gbuffer, const IntegratorSettings& settings) const {
  if (settings.spp == 0 && !(settings.time_budget_seconds > 0) && !(settings.target_relative_error > 0))
    throw std::invalid_argument("Vulkan backend: spp 0 needs a time budget or a target error");
  return impl_->bake(gbuffer, settings);
}

ProbeEstimate VulkanIntegrator::bake_probes(const std::vector<Vec3>& positions, const IntegratorSettings& settings) const {
  if (settings.spp == 0 && !(settings.time_budget_seconds > 0))
    throw std::invalid_argument("Vulkan backend: probes with spp 0 need a time budget");
  return impl_->bake_probes(positions, settings);
}

const VulkanDeviceInfo& VulkanIntegrator::device() const { return impl_->ctx->info(); }
std::string VulkanIntegrator::device_description() const {
  return device().name + " (" + to_string(device().type) + ")";
}
uint32_t VulkanIntegrator::max_paths() const { return impl_->paths; }
size_t VulkanIntegrator::path_state_bytes_per_path() const { return impl_->path_bytes(); }
size_t VulkanIntegrator::bvh_bytes() const {
  return impl_->scene.bvh.nodes.size() * (impl_->quantized_nodes ? kQuantizedNodeWords * 4 : sizeof(Bvh4Node)) +
         impl_->scene.bvh.leaf_triangles.size() * 48;
}
uint32_t VulkanIntegrator::bvh_node_count() const { return uint32_t(impl_->scene.bvh.nodes.size()); }
const std::vector<VulkanStageStatistics>& VulkanIntegrator::stage_statistics() const { return impl_->stats; }
double VulkanIntegrator::measure_incoherent_traversal(uint32_t ray_count, int repetitions) const {
  return impl_->traversal_bench(ray_count, repetitions);
}

}  // namespace exitance
