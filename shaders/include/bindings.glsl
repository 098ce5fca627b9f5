// Every buffer of the wavefront, one descriptor set. Binding numbers, counter slots, the parameter
// block and the scene records come from runtime/common/.../gpu_layout.h, shared with the host.
#include "exitance/common/gpu_layout.h"

layout(std430, set = 0, binding = kBindingParams) buffer ParamsBuffer { GpuParams params; };

// Specialization constant 2: true in the probe variants of generate and shade (work items are light
// probes, see regenerate and shade.comp); false compiles the probe code out of the lightmap kernels.
layout(constant_id = 2) const bool kProbeMode = false;

layout(std430, set = 0, binding = kBindingBvhNodes) readonly buffer NodeBuffer { uvec4 nodes[]; };  // bvh.glsl
layout(std430, set = 0, binding = kBindingBvhTriangles) readonly buffer LeafTriBuffer { vec4 leaf_tris[]; };  // 3 vec4 per leaf slot
layout(std430, set = 0, binding = kBindingTriangles) readonly buffer TriangleBuffer { GpuTriangle triangles[]; };
layout(std430, set = 0, binding = kBindingMaterials) readonly buffer MaterialBuffer { GpuMaterial materials[]; };
layout(std430, set = 0, binding = kBindingEmitterCdf) readonly buffer EmitterCdfBuffer { double emitter_cdf[]; };
layout(std430, set = 0, binding = kBindingEmitterTriangles) readonly buffer EmitterTriBuffer { uint emitter_tris[]; };
layout(std430, set = 0, binding = kBindingPunctualLights) readonly buffer PunctualBuffer { GpuPunctualLight punctual[]; };
layout(std430, set = 0, binding = kBindingPunctualCdf) readonly buffer PunctualCdfBuffer { double punctual_cdf[]; };
layout(std430, set = 0, binding = kBindingEnvironment) readonly buffer EnvironmentBuffer { double environment[]; };  // CDFs, packed rgb texels
layout(std430, set = 0, binding = kBindingStartPoints) readonly buffer StartPointBuffer { GpuSurfacePoint start_points[]; };
layout(std430, set = 0, binding = kBindingBatchItems) readonly buffer BatchItemBuffer { uint batch_items[]; };
layout(std430, set = 0, binding = kBindingCounters) coherent buffer CounterBuffer { uint counters[]; };
layout(std430, set = 0, binding = kBindingIndirect) buffer IndirectBuffer { uint indirect_args[]; };
// Per-point surfaces (textures, COLOR_0, alphaMode), packed (gpu_layout.h kBindingSurfaces).
layout(std430, set = 0, binding = kBindingSurfaces) readonly buffer SurfaceBuffer { vec4 surfaces[]; };

// Path state, structure of arrays, one entry per path slot.
layout(std430, set = 0, binding = kBindingPathWork) buffer PathWorkBuffer { uint path_work[]; };  // work item or kInvalid
layout(std430, set = 0, binding = kBindingPathDepth) buffer PathDepthBuffer { uint path_depth[]; };
layout(std430, set = 0, binding = kBindingPathRng) buffer PathRngBuffer { uvec4 path_rng[]; };  // PathSampler (item_hash, index, dimension, mode)
layout(std430, set = 0, binding = kBindingPathThroughput) buffer PathThroughputBuffer { vec4 path_throughput[]; };  // rgb, pdf of the ray
layout(std430, set = 0, binding = kBindingPathRayOrigin) buffer PathRayOriginBuffer { vec4 path_ray_o[]; };
layout(std430, set = 0, binding = kBindingPathRayDirection) buffer PathRayDirBuffer { vec4 path_ray_d[]; };
layout(std430, set = 0, binding = kBindingPathHit) buffer PathHitBuffer { vec4 path_hit[]; };  // t, triangle bits, b1, b2
layout(std430, set = 0, binding = kBindingShadowRays) buffer ShadowBuffer { ShadowRay shadow_rays[]; };  // params.shadow_slots per path
layout(std430, set = 0, binding = kBindingRayQueue) buffer RayQueueBuffer { uint ray_queue[]; };  // 2 x P (ping-pong)
layout(std430, set = 0, binding = kBindingShadowQueue) buffer ShadowQueueBuffer { uint shadow_queue[]; };  // P
layout(std430, set = 0, binding = kBindingResults) buffer ResultBuffer { float results[]; };  // [work][slot 0..K][rgb]
layout(std430, set = 0, binding = kBindingTexelSums) buffer AccumulatorBuffer { double acc_total[]; };  // [texel][total rgb, squared rgb]
layout(std430, set = 0, binding = kBindingBounceSums) buffer BounceAccumulatorBuffer { double acc_bounce[]; };  // [k][texel][rgb]
layout(std430, set = 0, binding = kBindingTexelSamples) buffer SampleCountBuffer { uint acc_samples[]; };
// [probe][coefficient][rgb], then [probe][rgb] squared L0 terms, then [light layer][probe][coefficient][rgb]
// (reduce_probes.comp; params.item_count_total probes)
layout(std430, set = 0, binding = kBindingProbeShSums) buffer ProbeShBuffer { double acc_probe_sh[]; };
// Per-bounce layer passes: the layers' atlas caches, in the probe SH sums' binding (gpu_layout.h kBindingBounceCache).
layout(std430, set = 0, binding = kBindingBounceCache) readonly buffer BounceCacheBuffer { float bounce_cache[]; };
// Path guiding: its header, locator, front, CDF and back sections, in the same binding (gpu_layout.h
// kBindingGuide); shaders/include/guide.glsl reads and learns into them.
layout(std430, set = 0, binding = kBindingGuide) buffer GuideBuffer { uint guide_words[]; };
layout(std430, set = 0, binding = kBindingProbeCounts) buffer ProbeCountBuffer { uint acc_probe_counts[]; };  // [probe][samples, back faces]
// Light subpaths: the batch's pool (gpu_layout.h kLightPool*; light_subpaths.comp writes it).
layout(std430, set = 0, binding = kBindingLightSubpaths) buffer LightPoolBuffer { uint light_pool[]; };

layout(push_constant) uniform Push {
  uint cur;    // which ray queue is read this iteration (0/1)
  uint mode;   // prepare kernel: what to prepare
} push;

void add_stat64(uint slot, uint value) {
  uint old = atomicAdd(counters[slot], value);
  if (old + value < old) atomicAdd(counters[slot + 1u], 1u);
}

// Adds 1 to counters[slot] for each invocation that calls it, with one atomicAdd per subgroup (an
// atomic per invocation on one address serializes: per-bounce passes count every gather).
void count_in_subgroup(uint slot) {
  uvec4 ballot = subgroupBallot(true);
  if (subgroupElect()) atomicAdd(counters[slot], subgroupBallotBitCount(ballot));
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
// batch's slots, per work item, kProbeExtraWords: the hit's albedo (x < 0: back face), the ray
// direction, and 1 + the light layer of what slot 0 met (0: nothing; probe light layers, reduce_probes).
uint result_index(uint work, uint slot) { return (work * (params.recorded + 1u) + slot) * 3u; }

// Per-bounce layer passes (one result slot, recorded = 0): per work item a flag, 1 when the texel's
// continuation ray met a single-sided back face (layer 0), after the batch's slots.
uint bounce_back_face_index(uint work) { return params.batch_work_total * 3u + work; }

const uint kProbeExtraWords = 7u;  // runtime/src/vulkan/probe_driver.h kProbeResultBytes
uint probe_extra_index(uint work) { return params.batch_work_total * 6u + work * kProbeExtraWords; }

void add_result(uint work, uint depth, vec3 value) {
  uint i = result_index(work, min(depth, params.recorded));
  results[i] += value.x;
  results[i + 1u] += value.y;
  results[i + 2u] += value.z;
}

// Directional texel state (gpu_layout.h): path p's first-continuation factor after the P
// throughputs, a texel's 9 L1 sums after all the texels' total sums.
uint sh1_factor_index(uint p) { return params.path_capacity + p; }
uint sh1_sum_index(uint texel) { return params.item_count_total * 6u + texel * 9u; }

// Directional texel batches: per work item 9 floats of L1 [axis][rgb] after all the bounce slots.
uint sh1_result_index(uint work) { return params.batch_work_total * (params.recorded + 1u) * 3u + work * 9u; }

void add_sh1_result(uint work, vec3 value, vec3 factor) {
  uint i = sh1_result_index(work);
  for (uint axis = 0u; axis < 3u; ++axis) {
    results[i + axis * 3u] += value.x * factor[axis];
    results[i + axis * 3u + 1u] += value.y * factor[axis];
    results[i + axis * 3u + 2u] += value.z * factor[axis];
  }
}

// --guiding auto's pilot passes (GpuParams::guiding & kGuidingAutoRecord): per work item its rays
// and guided vertices, as floats after the batch's bounce slots and L1 (gpu_layout.h kAutoCostWords).
// One writer at a time: a work item is one path, and every stage ends with a barrier.
uint auto_cost_index(uint work) {
  return params.batch_work_total * ((params.recorded + 1u) * 3u + (params.directional != 0u ? 9u : 0u)) + work * kAutoCostWords;
}

void add_auto_cost(uint work, uint slot, uint count) {
  if ((params.guiding & kGuidingAutoRecord) != 0u && count > 0u) results[auto_cost_index(work) + slot] += float(count);
}

// Light layers (GpuParams::light_layers, light_layers.h): after every other section of the batch's
// results, layer by layer, rgb per work item ([layer][work][rgb]: reduce.comp's texels read
// neighbouring work items together); a contribution adds to its light's layer as well as to its
// bounce slot (one writer: the path's own item).
uint light_result_index(uint work, uint layer) {
  return params.batch_work_total * params.light_result_words + (layer * params.batch_work_total + work) * 3u;
}

void add_light_result(uint work, uint layer, vec3 value) {
  if (params.light_layers == 0u) return;
  uint i = light_result_index(work, min(layer, params.light_layers - 1u));
  results[i] += value.x;
  results[i + 1u] += value.y;
  results[i + 2u] += value.z;
}

// The light layer of an emitting triangle: its material's (GpuMaterial::emission.w).
uint emitter_light_layer(uint tri) { return uint(materials[floatBitsToUint(triangles[tri].p0_material.w)].emission.w); }

// A contribution of path p: its E/pi slot, and on a directional texel batch its L1 through the
// path's first continuation (path.h sh1_direction_factor).
void add_path_result(uint p, uint work, uint depth, vec3 value) {
  add_result(work, depth, value);
  if (params.directional != 0u) add_sh1_result(work, value, path_throughput[sh1_factor_index(p)].xyz);
}
