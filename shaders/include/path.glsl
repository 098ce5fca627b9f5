// The wavefront's glue around the shared path steps (runtime/common/.../path.h): the same
// next-event estimation, continuation sampling and hit shading as the CPU reference, with the rays
// they ask for queued to the connect and extend stages instead of traced at once.
#include "exitance/common/path.h"
#include "exitance/common/light_layers.h"
#include "exitance/common/light_subpath_walk.h"
#include "guide.glsl"
#include "emitter_guide.glsl"

PathLimits path_limits() {
  PathLimits limits;
  limits.max_bounces = params.max_bounces;
  limits.rr_start = params.rr_start;
  limits.safety_cap = params.safety_cap;
  return limits;
}

// ---- Light subpaths (GpuParams::light_subpaths; light_subpaths.comp traces the batch's pool) ----
// Texel and probe path batches: never per-bounce passes or the runtime's change estimate.
bool light_subpaths_on() { return params.light_subpaths != 0u && params.bounce_flags == 0u && params.changed_light_pairs == 0u; }

// Whether path p's vertices connect to the pool: every texel and probe path of a batch with light
// subpaths, except under --guiding auto with light subpaths as its candidate (kGuidingAutoSubpaths),
// where only texel samples of the guided strategy connect and the others keep the path tracer's
// weights (an unbiased estimate either way, as on the CPU).
bool path_connects(uint p) {
  if (!light_subpaths_on()) return false;
  if (kProbeMode || (params.guiding & kGuidingAutoSubpaths) == 0u) return true;
  return auto_work_guided(path_work[p]);
}

// The depth of a path's fixed eye vertex x_0, never sampled from the light side: the texel, or the
// first hit of a probe's ray (whose vertices count their bounces from it).
uint eye_origin_depth() { return kProbeMode ? 1u : 0u; }

LightSubpathSampling light_subpath_start_of_params() {
  LightSubpathSampling s = light_subpaths_none();
  s.area_probability = params.light_subpath_start.x;
  s.punctual_scale = params.light_subpath_start.y;
  s.sky_probability = params.light_subpath_start.z;
  s.disk_density = params.light_subpath_start.w;
  return s;
}

// The pool's sampling as the eye's strategies weigh it: n_c = subpaths / vertices (0: an empty pool,
// the path tracer's weights).
LightSubpathSampling light_pool_sampling() {
  LightSubpathSampling s = light_subpath_start_of_params();
  uint vertices = light_pool[kLightPoolVertices], paths = light_pool[kLightPoolPaths];
  if (vertices > 0u && paths > 0u) {
    s.count = float(double(paths) / double(vertices));
    s.scale = float(double(vertices) / double(paths));
  }
  return s;
}

LightVertex light_pool_vertex(uint k) {
  uint w = kLightPoolVertexWord + k * kLightVertexWords;
  LightVertex v;
  v.position_depth = uintBitsToFloat(uvec4(light_pool[w], light_pool[w + 1u], light_pool[w + 2u], light_pool[w + 3u]));
  v.geometric_normal_layer = uintBitsToFloat(uvec4(light_pool[w + 4u], light_pool[w + 5u], light_pool[w + 6u], light_pool[w + 7u]));
  v.shading_normal_ratio = uintBitsToFloat(uvec4(light_pool[w + 8u], light_pool[w + 9u], light_pool[w + 10u], light_pool[w + 11u]));
  v.weight_a = uintBitsToFloat(uvec4(light_pool[w + 12u], light_pool[w + 13u], light_pool[w + 14u], light_pool[w + 15u]));
  v.b = uintBitsToFloat(uvec4(light_pool[w + 16u], light_pool[w + 17u], light_pool[w + 18u], light_pool[w + 19u]));
  return v;
}

// Path p's eye-vertex state (gpu_layout.h: path_throughput [2P + p]).
// After emitter guiding's 2P entries where it runs (emitter_learning_index; wavefront_buffers.h).
uint eye_subpath_index(uint p) { return (params.emitter_guide != 0u ? 4u : 2u) * params.path_capacity + p; }

EyeSubpathVertex stored_eye_subpath_vertex(uint p) {
  EyeSubpathVertex e = eye_subpath_vertex_none();
  e.sampling = light_pool_sampling();
  vec4 s = path_throughput[eye_subpath_index(p)];
  e.pdf_forward = s.x;
  e.eye_sum = s.y;
  return e;
}

// The cosine at the vertex path p's continuation ray left, toward the ray (path.h cos_left).
float stored_cos_left(uint p) { return path_throughput[eye_subpath_index(p)].z; }

// The shadow slot of a vertex's connection: the last (gpu_layout.h kShadowSlotsWith*).
bool is_connection_slot(uint k) { return light_subpaths_on() && k + 1u == params.shadow_slots; }

// Traces path p's pending shadow rays and adds what they carry to its work item (connect stage,
// and inline for a path that ends right after next-event estimation). Returns rays traced.
uint connect_shadow_rays(uint p, inout uint steps) {
  uint work = path_work[p], depth = path_depth[p];
  vec3 origin = path_ray_o[p].xyz;
  uint rays = 0u;
  for (uint k = 0u; k < params.shadow_slots; ++k) {
    uint slot = p * params.shadow_slots + k;
    vec4 contribution = shadow_rays[slot].contribution_state;
    if (contribution.w == kShadowNone) continue;
    ++rays;
    shadow_rays[slot].contribution_state.w = kShadowNone;
    if (contribution.w != kShadowTrace) continue;
    vec4 ray = shadow_rays[slot].direction_length;
    if (trace_any(origin, ray.xyz, ray.w, steps)) continue;
    if (is_connection_slot(k)) {  // a light subpath's: its vertex's depth and light layer
      uint vertex = floatBitsToUint(path_throughput[eye_subpath_index(p)].w);
      add_result(work, depth + (vertex & 0xFFFFu), contribution.xyz);
      add_light_result(work, vertex >> 16u, contribution.xyz);
    } else {
      if (params.emitter_guide != 0u) emitter_guide_learn_arrived(p, k);
      add_result(work, depth, contribution.xyz);
      if (params.light_layers != 0u) {
        // Slot 0: the area sample (layer in the low half of path_ray_o.w), 1: the punctual light (high half), 2: the sky.
        uint layers = floatBitsToUint(path_ray_o[p].w);
        add_light_result(work, k == 0u ? (layers & 0xFFFFu) : k == 1u ? (layers >> 16u) : kSkyLightLayer, contribution.xyz);
      }
    }
    if (params.directional != 0u) {
      // The texel's own next-event samples carry their shadow ray's direction; deeper ones the first continuation's.
      vec3 factor = path_throughput[sh1_factor_index(p)].xyz;
      if (depth == 0u) {
        SurfacePoint texel;
        texel.shading_normal = start_points[batch_items[params.batch_item_offset + work % params.batch_item_count]].shading_normal.xyz;
        factor = sh1_direction_factor(texel, ray.xyz);
      }
      add_sh1_result(work, contribution.xyz, factor);
    }
  }
  add_auto_cost(work, 0u, rays);
  return rays;
}

// At surface point x of path p (state: work, depth, throughput, rng): next-event estimation, then the
// continuation. Returns 0 when the path ends here, 1 when it continues with a ray; bit 1 set when
// shadow rays are pending.
uint sample_vertex(uint p, SurfacePoint x, vec3 throughput, inout PathSampler rng) {
  vec3 origin = offset_ray_origin(x.position, x.geometric_normal, params.scene_extent);
  path_ray_o[p] = vec4(origin, 0.0);
  ShadowRay area, punctual_light, environment;  // the environment ray exists only with an image sky (3 slots)
  // Guided batches: the vertex's record samples the front table's mixture (guide.glsl); probes stay
  // unguided. A directional texel's own vertex adds the defensive uniform component (path.h).
  bool directional_texel = !kProbeMode && params.directional != 0u && path_depth[p] == 0u;
  GuideVertex guide = guide_vertex_cosine();
  uint record = kGuideNoRecord;
  // --guiding auto: only the texel samples of the guided strategy look the guide up.
  bool guided_path = !kProbeMode && (params.guiding & kGuidingSample) != 0u;
  if (guided_path && (params.guiding & kGuidingAuto) != 0u) guided_path = auto_work_guided(path_work[p]);
  if (guided_path) {
    record = guide_record(x.position, x.shading_normal);
    guide = guide_vertex_of(record);
    uint guided = subgroupBallotBitCount(subgroupBallot(guide.guided_probability > 0.0));
    if (subgroupElect() && guided > 0u) add_stat64(kCounterGuidedVertices, guided);
    if (guide.guided_probability > 0.0) add_auto_cost(path_work[p], 1u, 1u);
  }
  if (directional_texel) guide = with_uniform_component(guide, kDirectionalUniformProbability);
  // Light subpaths: x_0 starts a fresh state; deeper vertices read the one their hit stored (shade.comp).
  bool subpaths = path_connects(p);
  EyeSubpathVertex eye = eye_subpath_vertex_none();
  if (subpaths) {
    if (path_depth[p] == eye_origin_depth()) {
      eye.sampling = light_pool_sampling();
    } else {
      eye = stored_eye_subpath_vertex(p);
    }
  }
  if (params.changed_light_pairs > 0u) {  // the runtime's change estimate: the edited lights alone
    environment = no_shadow_ray();
    uint pair;
    punctual_change_rays(x, throughput, params.punctual_count, params.changed_light_pairs, rng, punctual_light, area, pair);
    // Both of the pair's rays (slots 0 and 1) carry the edited light's change: its layer.
    uint layer = params.changed_light_layers[pair];
    if (params.light_layers != 0u) path_ray_o[p].w = uintBitsToFloat(layer | (layer << 16u));
  } else {
    EmitterLearning sources;
    // Emitter guiding (emitter_guide.glsl): texel samples only, as on the CPU.
    uint emitter_record = kGuideNoRecord;
    bool emitter_learns = false;
    EmitterGuide emitter = kProbeMode ? emitter_guide_none() : emitter_guide_site(p, x, emitter_record, emitter_learns);
    next_event_estimation(x, origin, throughput, guide, emitter, eye, rng, area, punctual_light, environment, sources);
    if (!kProbeMode && params.emitter_guide != 0u) emitter_guide_keep(p, emitter_record, emitter_learns, sources);
    if (params.light_layers != 0u) {
      // Which layers the shadow rays' light goes to, read back by connect_shadow_rays.
      uint area_layer = sources.area_triangle != kEmitterPatchNone ? emitter_light_layer(sources.area_triangle) : 0u;
      uint punctual_layer = sources.punctual_index != kEmitterPatchNone ? punctual_light_layer(sources.punctual_index, params.punctual_layers) : 0u;
      path_ray_o[p].w = uintBitsToFloat(area_layer | (punctual_layer << 16u));
    }
  }
  uint first = p * params.shadow_slots;
  shadow_rays[first] = area;
  shadow_rays[first + 1u] = punctual_light;
  bool shadows = area.contribution_state.w != kShadowNone || punctual_light.contribution_state.w != kShadowNone;
  if (params.shadow_slots > kShadowSlotsWithoutEnvironment) {
    shadow_rays[first + 2u] = environment;
    shadows = shadows || environment.contribution_state.w != kShadowNone;
  }
  DirectionSample d = sample_continuation(guide, x, rng);
  if (subpaths) {
    // One connection to a pool vertex picked uniformly (light_subpath_walk.h), in its own shadow slot.
    ShadowRay connection = no_shadow_ray();
    uint vertex = 0u;  // its depth | light layer << 16
    if (eye.sampling.count > 0.0) {
      float u = sample_1d(rng);
      uint count = light_pool[kLightPoolVertices];
      LightVertex y = light_pool_vertex(min(uint(double(u) * double(count)), count - 1u));
      connection = light_subpath_connection(eye.sampling, y, x, origin, throughput, guide,
                                            int(path_depth[p]) - int(eye_origin_depth()), eye, params.light_subpath_depth);
      vertex = floatBitsToUint(y.position_depth.w) | (floatBitsToUint(y.geometric_normal_layer.w) << 16u);
    }
    shadow_rays[first + params.shadow_slots - 1u] = connection;
    shadows = shadows || connection.contribution_state.w != kShadowNone;
    float cos_left = d.pdf > 0.0 ? dot(x.geometric_normal, d.direction) : 0.0;
    path_throughput[eye_subpath_index(p)] = vec4(eye.pdf_forward, eye.eye_sum, cos_left, uintBitsToFloat(vertex));
  } else if (light_subpaths_on()) {
    shadow_rays[first + params.shadow_slots - 1u] = no_shadow_ray();  // the batch's connection slot, unused by this path
  }
  uint pending = shadows ? 2u : 0u;
  if (directional_texel) path_throughput[sh1_factor_index(p)] = vec4(d.pdf > 0.0 ? sh1_direction_factor(x, d.direction) : vec3(0.0), 0.0);
  if (!(d.pdf > 0.0)) return pending;
  // w: the learning key of the ray's bin (guide.glsl), read back when its hit is shaded.
  uint key = (params.guiding & kGuidingLearn) != 0u ? guide_learning_key(record, guide, d.direction) : kInvalid;
  path_ray_d[p] = vec4(d.direction, uintBitsToFloat(key));
  path_throughput[p] = vec4(throughput * continuation_weight(guide, x, d), d.pdf);  // weight 1 for cosine vertices
  return pending | 1u;
}
