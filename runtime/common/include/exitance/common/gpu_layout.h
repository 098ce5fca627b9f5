// The lighting scene and the wavefront's parameters as the GPU reads them (std430), shared by the
// host upload (runtime/src/vulkan) and the kernels (shaders/), and by the CPU reference, which reads
// the same records, so the layouts cannot drift. Binding numbers and counter slots live here too.
#ifndef EXITANCE_COMMON_GPU_LAYOUT_H
#define EXITANCE_COMMON_GPU_LAYOUT_H
#include "exitance/common/dialect.h"
EXITANCE_NAMESPACE_BEGIN

// One scene triangle for shading: vertices, shading normals, and what light sampling needs.
struct GpuTriangle {
  vec4 p0_material;  // xyz vertex 0; w material index (uint bits)
  vec4 p1_emitter;   // xyz vertex 1; w 1 when NEE picks points on it (in the emitter list), else 0
  vec4 p2_instance;  // xyz vertex 2; w instance index (uint bits)
  vec4 n0;           // xyz shading normal at vertex 0
  vec4 n1;
  vec4 n2;
};

// A material's constant factors: all an untextured scene reads.
struct GpuMaterial {
  vec4 albedo_double_sided;  // xyz diffuse albedo (material.h); w 1 when double sided
  vec4 emission;             // xyz emitted radiance; w its light layer (light_layers.h), a whole number
  // x its emitted power per area (luminance of the mean emission, x2 when double sided), which x
  // GpuParams::emitter_inverse_power is the area density NEE picks a point on its emitters with
  // (so an emission edit rewrites this record and the CDF, not its emitters' triangles); yzw 0.
  vec4 emitter_power;
};

// What a material needs where it varies per point (scenes with GpuParams::surface_flags &
// kSurfaceTextured): its factors before the diffuse conversion, its textures and its alphaMode.
struct GpuMaterialSurface {
  vec4 base_color_metallic;    // xyz baseColorFactor (linear); w metallic
  vec4 base_offset_scale;      // base colour texture's KHR_texture_transform: xy offset, zw scale
  vec4 emissive_offset_scale;  // the emissive texture's
  vec4 rotations_alpha;        // x base colour texture rotation, y emissive rotation, z alpha cutoff, w base alpha
  vec4 textures_mode;          // uint bits: x base colour texture, y emissive texture (kNoTexture: none),
                               // z tex_coord sets (base | emissive << 8), w alpha mode (surface_alpha.h)
};
const uint kNoTexture = 0xFFFFFFFFu;

// One texture: its texels (vec4 rgb + alpha, linear floats as the CPU reference holds them) start
// at texel_offset in the texels' part of the surface words, row by row from the top.
struct GpuTexture {
  uint texel_offset;
  uint width;
  uint height;
  uint wrap_alpha;  // wrap_s | wrap_t << 8 (texture_sampling.h), bit 16: the texture has alpha
};
const uint kTextureHasAlpha = 0x10000u;

// GpuParams::surface_flags: what of the per-point surface data a scene has. 0: constant materials,
// and traversal never looks at materials.
const uint kSurfaceTextured = 1u;        // materials are evaluated per point (GpuMaterialSurface)
const uint kSurfaceVertexColor = 2u;     // per-corner COLOR_0 rgb multiplies the base colour
const uint kSurfaceVertexAlpha = 4u;     // per-corner COLOR_0 alpha multiplies coverage
const uint kSurfaceAlphaMaterials = 8u;  // some material is MASK or BLEND: traversal tests hits

struct GpuPunctualLight {
  vec4 position_type;        // xyz position; w type (uint bits: kPunctualPoint/Spot/Directional)
  vec4 direction_cos_inner;  // xyz direction the light travels; w spot cos(inner cone)
  vec4 intensity_cos_outer;  // xyz W/sr (point, spot) or W/m^2 (directional); w spot cos(outer cone)
};

// A point the estimator starts from: a lightmap texel (or a probe: position only).
struct GpuSurfacePoint {
  vec4 position;
  vec4 geometric_normal;
  vec4 shading_normal;
};

// ---- Next-event estimation's shadow rays (path.h), kept per path slot between the shade and connect stages ----
// A shadow ray from the vertex's offset origin: unit direction and length, and what it adds when
// unoccluded (path throughput included). state: kShadowNone, kShadowTrace, or kShadowCountOnly
// (counted as a traced ray, as the reference counts it, but its segment has zero length).
// Bounce layers a texel batch records at most (reduce.comp keeps one running sum per layer).
const uint kMaxRecordedLayers = 16u;
const uint kShadowRaysPerVertex = 3u;  // area light, punctual light, environment
// The wavefront's shadow-ray buffer has room for all three per path slot, but its stride is
// GpuParams::shadow_slots: 2 unless the sky is an image, since a third slot written per vertex cost
// 7 % of the shade stage's GPU time on the H200 (0.327 -> 0.304 s, bench/results/vulkan-gpu.md).
const uint kShadowSlotsWithoutEnvironment = 2u;
const float kShadowNone = 0.0f;
const float kShadowTrace = 1.0f;
const float kShadowCountOnly = 2.0f;

struct ShadowRay {
  vec4 direction_length;    // xyz unit direction, w length (+inf for the environment)
  vec4 contribution_state;  // xyz contribution when unoccluded, w state
};

// Everything the kernels read that is not per item. Updated in place between batches.
struct GpuParams {
  vec4 sky;             // rgb constant sky radiance
  vec4 bench_lo;        // traversal bench: scene bounds
  vec4 bench_hi;
  float scene_extent;   // largest side of the scene bounds (ray offset floor)
  uint emitter_count;
  float emitter_inverse_power;  // 1 / the emitters' total power (GpuMaterial::emitter_power); 0: none
  uint punctual_count;
  uint recorded;        // K: recorded bounce layers; result slot K gathers the deeper ones
  int max_bounces;
  int rr_start;
  int safety_cap;
  uint path_capacity;   // P: path slots
  uint seed_lo;
  uint seed_hi;
  uint batch_item_offset;  // first entry of batch_items in this batch
  uint batch_item_count;   // n
  uint batch_sample_begin;
  uint batch_sample_count;
  uint batch_work_total;   // n * samples
  uint collect_stats;
  uint item_count_total;   // items (texels, probes) of the whole bake: the bounce accumulator's stride
  uint probe_spp;          // probes: samples per probe of the whole bake (0xFFFFFFFF: until the time budget)
  uint sampling_strategy;  // kStrategy* (path.h)
  uint sampler_mode;       // kSampler* (path_sampler.h); "sampler" is a GLSL keyword
  uint surface_flags;      // kSurface* above
  uint environment_width;  // equirect sky (environment_map.h) in texels; 0: the constant sky
  uint environment_height;
  uint shadow_slots;       // shadow rays kept per path slot: 3 with an environment map, else 2
  uint directional;        // texel batches: 1 = also estimate the L1 SH layers (DirectionalMode::Sh1)
  uint bounce_flags;       // texel batches: 0 = path tracing; else a per-bounce layer pass (kBouncePass | ...)
  uint bounce_layer;       // per-bounce layer pass: k, the layer B_k estimated (0 = direct light)
  uint guiding;            // texel path batches: kGuiding* bits (the guide buffer, kBindingGuide); 0 = cosine
  uint traversal_steps;    // a ray's traversal steps beyond which it is a counted fault (bvh.glsl;
                           // GpuScene::traversal_step_bound; a parameter, not a specialization
                           // constant, so one compiled kernel serves every scene's BVH)
  uint changed_light_pairs;  // texel batches: 0 = the estimator; n > 0 = the change of direct light from n edited
                             // punctual lights (path.h punctual_change_rays), pairs of records after the scene's own
  uint light_layers;         // texel path batches: 0 = none; L > 0 = also sum each contribution into its light
                             // layer (light_layers.h), L layers of rgb per work item after every other slot
  uint punctual_layers;      // light layers of punctual lights (light_layers.h punctual_light_layer)
  uint light_result_words;   // result words per work item before the light layers' section (bindings.glsl)
  uint emitter_guide;        // texel path batches: word offset of emitter guiding's section in the guide buffer
                             // (kEmitterGuide* below); 0 = the default next-event sampling
  // A change estimate with light layers: pair k's change goes to layer changed_light_layers[k].
  uint changed_light_layers[8];  // kMaxChangedLightPairs
  // Light subpaths (light_subpaths.h; texel path batches, bake --light-paths on): the batch's pool
  // (kBindingLightSubpaths) is traced from this many subpaths before its paths start; 0 = none.
  uint light_subpaths;
  uint light_subpath_capacity;   // pool vertices the binding holds (a pool is cut to the subpaths that fit)
  int light_subpath_depth;       // the deepest vertex kept: the eye paths' bounce limit (or the safety cap)
  vec4 light_subpath_start;      // LightSubpathSampling: area_probability, punctual_scale, sky_probability, disk_density
  vec4 light_subpath_sphere;     // the bounds' sphere where the sky's and directional lights' subpaths enter: centre, radius
};

// The most edited punctual lights a change estimate carries (GpuParams::changed_light_pairs; the
// runtime restarts beyond it): the punctual light buffer has room for their pairs from the start,
// so the first light edit allocates nothing.
const uint kMaxChangedLightPairs = 8u;

// Descriptor bindings of the wavefront (one set).
const uint kBindingParams = 0u;
const uint kBindingBvhNodes = 1u;
const uint kBindingBvhTriangles = 2u;
const uint kBindingTriangles = 3u;
const uint kBindingMaterials = 4u;
const uint kBindingEmitterCdf = 5u;
const uint kBindingEmitterTriangles = 6u;
const uint kBindingPunctualLights = 7u;
const uint kBindingPunctualCdf = 8u;
const uint kBindingStartPoints = 9u;
const uint kBindingBatchItems = 10u;
const uint kBindingCounters = 11u;
const uint kBindingIndirect = 12u;
const uint kBindingPathWork = 13u;
const uint kBindingPathDepth = 14u;
const uint kBindingPathRng = 15u;
const uint kBindingPathThroughput = 16u;
const uint kBindingPathRayOrigin = 17u;
const uint kBindingPathRayDirection = 18u;
const uint kBindingPathHit = 19u;
const uint kBindingShadowRays = 20u;
const uint kBindingRayQueue = 21u;
const uint kBindingShadowQueue = 22u;
const uint kBindingResults = 23u;
const uint kBindingTexelSums = 24u;
const uint kBindingBounceSums = 25u;
const uint kBindingTexelSamples = 26u;
const uint kBindingProbeShSums = 27u;
const uint kBindingProbeCounts = 28u;
// Per-point surfaces, one vec4 array (a 1-element stand-in unless the scene is textured): lavapipe
// allows 32 storage buffers per stage, so they share one binding. Word 0 is a header (uint bits:
// first word of the texture records, of the corner UVs, of the corner colours, of the texels); then
// kMaterialSurfaceWords per material (GpuMaterialSurface), one word per texture (GpuTexture), per
// triangle corner uv0 and lightmap uv (xy, zw), per corner COLOR_0 rgba (only with kSurfaceVertexColor),
// and the texels (rgb, alpha), each texture's from its texel_offset.
const uint kBindingSurfaces = 29u;
const uint kSurfaceHeaderWords = 1u;
const uint kMaterialSurfaceWords = 5u;
// The image sky, one array of doubles (a 1-element stand-in when the sky is constant), for the same
// reason: the marginal CDF over rows (height + 1 entries), then one CDF per row (width + 1 entries
// each), then the texels' rgb floats packed two to a double (offsets: environment_map.h).
const uint kBindingEnvironment = 30u;
// Directional (L1 SH) texels keep their state in existing buffers, for the same reason: per path
// the first continuation's sh1_direction_factor (xyz) at path_throughput[path_capacity + p], per texel
// the 9 L1 sums [texel][axis][rgb] after the texel sums (acc_total from item_count_total * 6), and
// per sample the L1 results after the batch's bounce slots (bindings.glsl sh1_result_index).
// The per-bounce mode's layer passes (GpuParams::bounce_flags, shaders/include/bounce_pass.glsl)
// read the layers' dilated atlas caches from the probe SH sums' binding, which a lightmap bake
// leaves unused, as floats: kBounceCacheHeaderWords words of header (uint bits, kBounceCache* below),
// then per scene triangle its instance (uint bits) and lightmap UVs (3 x xy), per instance its page
// (int bits, -1: none) and scale_offset, per page width, height and first page texel (uint bits),
// then per layer kBounceCacheTexelWords per page texel (BounceLayerCache's channels interleaved:
// rgb, lit, position, geometric normal). Per work item a back-face flag follows the batch's result
// slots (bounce_back_face_index).
const uint kBindingBounceCache = kBindingProbeShSums;
const uint kBounceCacheTriangles = 0u;      // header word: first word of the triangle table; +1 its count
const uint kBounceCacheInstances = 2u;      // first word of the instance table; +1 its count
const uint kBounceCachePages = 4u;          // first word of the page table; +1 its count
const uint kBounceCacheLayers = 6u;         // first word of layer 0; +1 words per layer
const uint kBounceCacheHeaderWords = 8u;
const uint kBounceCacheTriangleWords = 7u;
const uint kBounceCacheInstanceWords = 5u;
const uint kBounceCachePageWords = 3u;
const uint kBounceCacheTexelWords = 10u;
const uint kBounceCacheDilation = 2u;       // rings of gutter texels filled around charts (a bilinear footprint reaches one past)
const uint kBouncePass = 1u;                // bounce_flags: this batch estimates layer bounce_layer
const uint kBounceTraceFirst = 2u;          // at layer 0 a gather hit takes a direct-light sample, not the cache
// Path guiding (--guiding grid, issue 11; docs/lighting-core.md "Grid guiding on the Vulkan
// backend") keeps ALL its data in the same binding, as uints (a lightmap path-tracing bake uses
// neither probe sums nor layer caches): a header of kGuideHeaderWords, then sections at the word
// offsets the header gives:
//   locator  how a surface point (position, shading normal) finds its record; its layout depends on
//            the header's locator kind. kGuideLocatorGrid: kGuideGridWords words (origin xyz, cell
//            size as floats; cells along x, y, z), then per (cell, normal class) the record or
//            kGuideNoRecord, cell (z * ny + y) * nx + x, class guided_direction.h guide_normal_class.
//            Another kind (a tree descent to a bin) adds its own locator section and reuses the rest.
//   front    per record kGuideFrontWords: guided probability (float), Lbar (float), normal class, 0
//   cdf      per record kGuideBins + 1 floats (guided_direction.h's CDF; a GuideVertex's cdf handle
//            is the word offset of its record's CDF)
//   back     per record and bin kGuideBackWords: fixed-point sum (lo, hi words) and count, added to
//            with integer atomics during learning passes; between passes fold_guide.comp folds and
//            clears them (common/guide_fold.h, GridGuidingCache::swap's code) and rewrites front and
//            cdf, with no host round trip.
//   learned  per record and bin kGuideLearnedWords: the fold's learned radiance and weight (floats),
//            GridGuidingCache's radiance and weight tables; read back once, at the end of a bake.
// The header also holds the fixed-point scale (a double as lo, hi words) and the target cap (float)
// of common/guide_learning.h guide_fixed_point.
const uint kBindingGuide = kBindingProbeShSums;
const uint kGuideLocatorKind = 0u;      // header word: kGuideLocator*
const uint kGuideRecordCount = 1u;
const uint kGuideLocatorOffset = 2u;    // header words: first word of each section
const uint kGuideFrontOffset = 3u;
const uint kGuideCdfOffset = 4u;
const uint kGuideBackOffset = 5u;
const uint kGuideFixedUnits = 6u;       // + 7: the double's lo, hi words
const uint kGuideFixedCap = 8u;
const uint kGuideAutoTexels = 9u;      // --guiding auto: first word of the per-texel strategy words (0: none)
const uint kGuideAutoSums = 10u;       // first word (even) of the per-texel strategy sums (doubles)
const uint kGuideAutoPilot = 11u;      // pilot samples per texel (GuidingChoice::pilot)
const uint kGuideAutoStatisticsFrom = 12u;  // first pilot sample whose values are summed
const uint kGuideLearnedOffset = 13u;  // first word of the learned section (grid guiding)
const uint kGuideHeaderWords = 16u;
const uint kGuideLocatorNone = 0u;      // every vertex samples cosine
const uint kGuideLocatorGrid = 1u;
const uint kGuideGridWords = 8u;        // origin xyz, cell size, cells x y z, 0
// kGuideLocatorSvo (--guiding svo; core/svo_guiding_fields.h's device contract): kGuideSvoWords words
// (octree origin xyz, size as floats; depth, node count, bin count, 0), then per node 2 words
// (first child, child mask | level << 8), per node its bin (or kGuideNoRecord), per bin and normal
// class its record (or kGuideNoRecord). Its back section holds no learning sums but per node and
// class a vertex count (integer atomics in passes with kGuidingCount), read back for the next
// rebuild's bins (SvoGuidingFields::import_counts). Front: probability, 0, class, 0.
const uint kGuideLocatorSvo = 2u;
const uint kGuideSvoWords = 8u;
const uint kGuideFrontWords = 4u;
const uint kGuideBackWords = 3u;
const uint kGuideLearnedWords = 2u;
const uint kGuideNoRecord = 0xFFFFFFFFu;
// Emitter guiding (--emitter-guiding on; core/emitter_guiding_cache.h, common/guided_emitters.h;
// docs/lighting-core.md "Emitter guiding on the Vulkan backend"): one more section of the guide
// buffer, after any other guide's, at the word GpuParams::emitter_guide gives. Its first
// kEmitterGuideHeaderWords words hold the word offsets of its tables and their sizes:
//   locator   kGuideGridWords words as kGuideLocatorGrid's, then per (cell, normal class) its record
//   tables    per emitter its first patch << 3 | level, per patch its first and end emitter, per scene
//             triangle its emitter (guided_emitters.h EmitterGuide's tables)
//   front     per record 2 floats: the area lights' and the punctual lights' guided probability
//   cdf       per record patch_count + 1 floats; punctual cdf: per record punctual_count + 1 floats
//   fold      what the fold reads besides the learned sums: per patch its default probability
//             (float), per punctual light its default probability, per cluster its first patch then
//             the patch count (EmitterPatches::cluster_first)
//   back      per record and patch kGuideBackWords (fixed-point sum lo, hi; count); punctual back: per
//             record and light 2 words (sum lo, hi). Added to by integer atomics when a vertex that
//             learns (EmitterGuidingCache::learning of its sample) sees its shadow ray arrive; between
//             passes fold_emitter_guide.comp folds and clears them (common/emitter_guide_fold.h,
//             EmitterGuidingCache::swap's code) and rewrites front and cdf, counting the records that
//             sample what they learned in header word kEmitterGuideSampling
//   learned   per record and patch kEmitterGuideLearnedWords: cumulative learned sum (a double as
//             lo, hi words) and unoccluded samples; punctual learned: per record and light the sum
//             (a double). The fold's state, on the device alone; read back once, at the end of a bake.
// Per path, the vertex's emitter record and what its shadow rays learn wait in path_throughput
// [2P + 2p] and [2P + 2p + 1] (record, patch, value, punctual light; punctual value, learns) from
// next-event estimation to the connect stage, and the record until the continuation's hit is shaded
// (its MIS weight reads the mixture's density).
const uint kEmitterGuideLocator = 0u;
const uint kEmitterGuideRecords = 1u;
const uint kEmitterGuidePatches = 2u;
const uint kEmitterGuidePunctual = 3u;
const uint kEmitterGuideEmitterPatch = 4u;
const uint kEmitterGuidePatchEmitters = 5u;
const uint kEmitterGuideTriangleEmitter = 6u;
const uint kEmitterGuideFront = 7u;
const uint kEmitterGuideCdf = 8u;
const uint kEmitterGuidePunctualCdf = 9u;
const uint kEmitterGuideBack = 10u;
const uint kEmitterGuidePunctualBack = 11u;
const uint kEmitterGuideFixedUnits = 12u;  // + 13: the double's lo, hi words
const uint kEmitterGuideFixedCap = 14u;
const uint kEmitterGuideDefault = 15u;          // per patch its default probability
const uint kEmitterGuidePunctualDefault = 16u;  // per punctual light its default probability
const uint kEmitterGuideClusterFirst = 17u;     // cluster count + 1 words
const uint kEmitterGuideClusters = 18u;
const uint kEmitterGuideMix = 19u;              // float: the learned share where a record gains
const uint kEmitterGuideLearned = 20u;
const uint kEmitterGuidePunctualLearned = 21u;
const uint kEmitterGuideSampling = 22u;         // the fold's count of records sampling what they learned
const uint kEmitterGuideHeaderWords = 24u;
const uint kEmitterGuideFrontWords = 2u;
const uint kEmitterGuidePunctualBackWords = 2u;
const uint kEmitterGuideLearnedWords = 3u;
const uint kEmitterGuidePunctualLearnedWords = 2u;
const uint kGuidingSample = 1u;         // GpuParams::guiding: vertices sample the front table's mixture
const uint kGuidingLearn = 2u;          // and their continuation rays add to the back table
const uint kGuidingCount = 4u;          // SVO locator: vertices count themselves per (node, class)
// --guiding auto (core/guiding_choice.h; docs/lighting-core.md "`--guiding auto` on the Vulkan backend"):
// two more sections of the grid's guide buffer. Per texel one strategy word (common/
// guiding_auto_strategy.h: measuring, coin, decided, guided), which picks each texel sample's
// strategy and sampler stream; only guided samples look up the guide. Per texel and strategy
// [unguided, guided] kAutoSumDoubles doubles (StrategySums: samples, sum, squares, cubes, fourth
// powers of the luminance of E/pi, rays, guided vertices), added by the accumulate stage in sample
// order (one writer per texel, so bit-identical per seed) for samples [statistics_from, pilot), read
// back once when the pilot is complete. While they are recorded each work item also counts its rays
// and guided vertices, as 2 floats after the batch's result slots (bindings.glsl auto_cost_index).
const uint kGuidingAuto = 8u;           // each texel sample's strategy from its strategy word
const uint kGuidingAutoRecord = 16u;    // pilot passes: count work items' costs, add the strategy sums
// With kGuidingAuto: the candidate is light subpaths, not the grid: a texel sample of the guided
// strategy connects to the batch's pool (path.glsl path_connects), the others are the path tracer's
// alone (their MIS weights without the connections), and no vertex samples the grid's table.
const uint kGuidingAutoSubpaths = 32u;
const uint kAutoSumDoubles = 7u;
const uint kAutoCostWords = 2u;         // per work item: rays, guided vertices (floats)
// Light subpaths on the wavefront (GpuParams::light_subpaths; shaders/wavefront/light_subpaths.comp):
// the batch's pool, as uints. Header words kLightPool*; from word kLightPoolCounts one word per
// subpath (its vertex count, then the exclusive prefix sum: where its vertices start); from word
// kLightPoolVertexWord the vertices, kLightVertexWords each (light_subpaths.h LightVertex), in
// subpath order, so the pool is the same for a seed whatever the schedule. lavapipe allows 32
// storage buffers per stage: this is the 32nd binding.
const uint kBindingLightSubpaths = 31u;
const uint kLightPoolVertices = 0u;   // header: vertices kept
const uint kLightPoolPaths = 1u;      // header: subpaths whose vertices all fit (the pool's subpath count)
const uint kLightPoolCounts = 4u;
const uint kLightPoolMostPaths = 262144u;  // 2^18 subpaths per pool at most
const uint kLightPoolVertexWord = kLightPoolCounts + kLightPoolMostPaths;
const uint kLightVertexWords = 20u;
const uint kLightSubpathsCount = 0u;    // light_subpaths.comp modes (push constant): count each subpath's vertices,
const uint kLightSubpathsOffsets = 1u;  // their prefix sums (one workgroup),
const uint kLightSubpathsWrite = 2u;    // then trace again, writing them
// Per path, the eye vertex's light-subpath state (path.h EyeSubpathVertex) from next-event
// estimation to its continuation's hit, in one vec4 at path_throughput [2P + p] (the section
// emitter guiding's learning uses, which light subpaths are not combined with on this backend):
// pdf_forward, eye_sum, cos_left (path.h: the cosine at the vertex toward its continuation), and
// the pending connection's light-vertex depth | light layer << 16 (uint bits). The connection's
// shadow ray is the last slot (GpuParams::shadow_slots - 1): the environment's slot when the sky is
// constant (3 slots: the buffer's size already), a fourth with an environment map.
const uint kShadowSlotsWithConnection = 3u;
const uint kShadowSlotsWithEnvironmentAndConnection = 4u;
const uint kBindingCount = 32u;

// Counter slots (uint each; statistics are 64-bit lo/hi pairs).
const uint kCounterRayQueue0 = 0u;  // ray queue sizes, ping-pong (0 and 1)
const uint kCounterShadowQueue = 2u;
const uint kCounterNextWork = 3u;
const uint kCounterNonfinite = 4u;
const uint kCounterRaysPrimary = 5u;
const uint kCounterRaysBounce = 6u;
const uint kCounterRaysShadow = 7u;
const uint kCounterBounceGathers = 8u;     // per-bounce passes: gather rays that hit a surface,
const uint kCounterBounceTexelless = 9u;   // of those estimated on the fly (no lit texel there),
const uint kCounterBounceBackFaces = 10u;  // of those single-sided back faces
const uint kCounterRaysLightSubpaths = 11u;  // light subpaths' rays (both of light_subpaths.comp's traces)
const uint kCounterGuidedVertices = 12u;   // guided batches: vertices with a learned record (lo, hi)
const uint kCounterStatExtendActive = 16u;  // lanes active inside traversal loops / lanes launched there
const uint kCounterStatExtendLaunched = 18u;
const uint kCounterStatConnectActive = 20u;
const uint kCounterStatConnectLaunched = 22u;
const uint kCounterStatShadeItems = 24u;
const uint kCounterStatShadeLanes = 26u;
// Device faults: counted, never silent, and each makes the host throw (wavefront_batch.cpp).
// A traversal that needed more stack entries or steps than a valid BVH allows (bvh.glsl), and a
// work claim that did not advance the work counter (kernel_prelude.glsl regenerate).
const uint kCounterFaultTraversal = 28u;
const uint kCounterFaultWorkClaim = 29u;
const uint kCounterLightSubpaths = 30u;        // light subpaths in the batch's pool (kLightPoolPaths)
const uint kCounterLightSubpathVertices = 31u;  // and their vertices
const uint kCounterCount = 32u;

// Light probes: random streams path_sampler(seed, kProbeRngStreamBase + probe, sample), and stratified
// sets of kProbeStratifiedSetSize consecutive samples (sampling.h probe_direction).
const uint64_t kProbeRngStreamBase = 1099511627776ul;  // 2^40
// Light subpaths: path_sampler(seed, kLightSubpathStreamBase + subpath, key) (light_subpaths.h).
const uint64_t kLightSubpathStreamBase = 2199023255552ul;  // 2^41
const uint kProbeStratifiedSetSize = 256u;

EXITANCE_NAMESPACE_END
#endif
