// Every buffer of the wavefront, one descriptor set. Host side: runtime/src/vulkan/vulkan_integrator.cpp
// (enum Binding) must list the same numbers.

layout(std430, set = 0, binding = 0) buffer ParamsBuffer {
  vec4 sky;               // rgb constant sky radiance
  float scene_extent;     // largest side of the scene bounds (ray offset floor)
  uint emitter_count;
  uint punctual_count;
  uint recorded;          // K: recorded bounce layers; result slot K gathers the deeper ones
  int max_bounces;
  int rr_start;
  int safety_cap;
  uint path_capacity;     // P: path slots
  uint seed_lo, seed_hi;
  uint batch_texel_offset;  // first entry of batch_texels in this batch
  uint batch_texel_count;   // n
  uint batch_sample_begin;
  uint batch_sample_count;
  uint batch_work_total;    // n * samples
  uint collect_stats;
  uint texel_count_total;   // live texels of the whole bake (bounce accumulator stride)
  uint pad0;
  uint probe_spp;           // probes: samples per probe of the whole bake (0xFFFFFFFF: until the time budget)
  uint pad2;
  vec4 bench_lo;            // traversal bench: scene bounds
  vec4 bench_hi;
} params;

// Specialization constant 2: true in the probe variants of generate and shade (work items are light
// probes, see regenerate and shade.comp); false compiles the probe code out of the lightmap kernels.
layout(constant_id = 2) const bool kProbeMode = false;

layout(std430, set = 0, binding = 1) readonly buffer NodeBuffer { uvec4 nodes[]; };       // BVH4 nodes: 4 uvec4 quantized or 7 float (bvh.glsl)
layout(std430, set = 0, binding = 2) readonly buffer LeafTriBuffer { vec4 leaf_tris[]; }; // 3 vec4 per triangle
layout(std430, set = 0, binding = 3) readonly buffer TriShadingBuffer { vec4 tri_shading[]; };  // 6 vec4 per scene triangle
layout(std430, set = 0, binding = 4) readonly buffer MaterialBuffer { vec4 materials[]; };      // 2 vec4 per material
layout(std430, set = 0, binding = 5) readonly buffer EmitterCdfBuffer { double emitter_cdf[]; };
layout(std430, set = 0, binding = 6) readonly buffer EmitterTriBuffer { uint emitter_tris[]; };
layout(std430, set = 0, binding = 7) readonly buffer PunctualBuffer { vec4 punctual[]; };       // 3 vec4 per light
layout(std430, set = 0, binding = 8) readonly buffer PunctualCdfBuffer { double punctual_cdf[]; };
layout(std430, set = 0, binding = 9) readonly buffer TexelBuffer { vec4 texels[]; };           // 3 vec4 per texel
layout(std430, set = 0, binding = 10) readonly buffer BatchTexelBuffer { uint batch_texels[]; };
layout(std430, set = 0, binding = 11) coherent buffer CounterBuffer { uint counters[]; };
layout(std430, set = 0, binding = 12) buffer IndirectBuffer { uint indirect_args[]; };

// Path state, structure of arrays, one entry per path slot.
layout(std430, set = 0, binding = 13) buffer PathWorkBuffer { uint path_work[]; };      // work item or kInvalid
layout(std430, set = 0, binding = 14) buffer PathDepthBuffer { uint path_depth[]; };
layout(std430, set = 0, binding = 15) buffer PathRngBuffer { u64vec2 path_rng[]; };     // (state, increment)
layout(std430, set = 0, binding = 16) buffer PathThroughputBuffer { vec4 path_throughput[]; };  // rgb, pdf of the ray
layout(std430, set = 0, binding = 17) buffer PathRayOriginBuffer { vec4 path_ray_o[]; };
layout(std430, set = 0, binding = 18) buffer PathRayDirBuffer { vec4 path_ray_d[]; };
layout(std430, set = 0, binding = 19) buffer PathHitBuffer { vec4 path_hit[]; };        // t, triangle bits, b1, b2
layout(std430, set = 0, binding = 20) buffer ShadowBuffer { vec4 shadow_rays[]; };      // 2 rays x (dir|tmax, contrib|valid)
layout(std430, set = 0, binding = 21) buffer RayQueueBuffer { uint ray_queue[]; };      // 2 x P (ping-pong)
layout(std430, set = 0, binding = 22) buffer ShadowQueueBuffer { uint shadow_queue[]; };// P
layout(std430, set = 0, binding = 23) buffer ResultBuffer { float results[]; };         // [work][slot 0..K][rgb]
layout(std430, set = 0, binding = 24) buffer AccumulatorBuffer { double acc_total[]; }; // [texel][total rgb, squared rgb]
layout(std430, set = 0, binding = 25) buffer BounceAccumulatorBuffer { double acc_bounce[]; };  // [k][texel][rgb]
layout(std430, set = 0, binding = 26) buffer SampleCountBuffer { uint acc_samples[]; };
layout(std430, set = 0, binding = 27) buffer ProbeShBuffer { double acc_probe_sh[]; };       // [probe][coefficient][rgb]
layout(std430, set = 0, binding = 28) buffer ProbeCountBuffer { uint acc_probe_counts[]; };  // [probe][samples, back faces]

// Counter slots.
const uint kRayCount0 = 0u;       // ray queue sizes, ping-pong
const uint kShadowCount = 2u;
const uint kNextWork = 3u;
const uint kNonfinite = 4u;
const uint kRaysPrimary = 5u;
const uint kRaysBounce = 6u;
const uint kRaysShadow = 7u;
const uint kPathsStarted = 8u;
// Statistics (64-bit as lo/hi pairs): lanes active inside traversal loops / lanes launched there.
const uint kStatExtendActive = 16u;
const uint kStatExtendLaunched = 18u;
const uint kStatConnectActive = 20u;
const uint kStatConnectLaunched = 22u;
const uint kStatShadeItems = 24u;
const uint kStatShadeLanes = 26u;

layout(push_constant) uniform Push {
  uint cur;    // which ray queue is read this iteration (0/1)
  uint mode;   // prepare kernel: what to prepare
} push;

void add_stat64(uint slot, uint value) {
  uint old = atomicAdd(counters[slot], value);
  if (old + value < old) atomicAdd(counters[slot + 1u], 1u);
}

// Appends to a queue with one atomicAdd per subgroup: ballot, count, elect, broadcast.
uint queue_append(uint counter_slot) {
  uvec4 ballot = subgroupBallot(true);
  uint count = subgroupBallotBitCount(ballot);
  uint base = 0u;
  if (subgroupElect()) base = atomicAdd(counters[counter_slot], count);
  base = subgroupBroadcastFirst(base);
  return base + subgroupBallotExclusiveBitCount(ballot);
}

// Texels: per work item, slots 0..K of E/pi by bounce. Probes (K = 1): slot 0 the radiance met by the
// probe ray (sky or emission), slot 1 the path estimate of E/pi at its hit, then after all the
// batch's slots, per work item, the hit's albedo (x < 0: back face) and the ray direction.
uint result_index(uint work, uint slot) { return (work * (params.recorded + 1u) + slot) * 3u; }

uint probe_extra_index(uint work) { return params.batch_work_total * 6u + work * 6u; }

void add_result(uint work, uint depth, vec3 value) {
  uint i = result_index(work, min(depth, params.recorded));
  results[i] += value.x;
  results[i + 1u] += value.y;
  results[i + 2u] += value.z;
}
