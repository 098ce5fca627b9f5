// The wavefront's glue around the shared path steps (runtime/common/.../path.h): the same
// next-event estimation, continuation sampling and hit shading as the CPU reference, with the rays
// they ask for queued to the connect and extend stages instead of traced at once.
#include "exitance/common/path.h"
#include "exitance/common/light_layers.h"
#include "guide.glsl"
#include "emitter_guide.glsl"

PathLimits path_limits() {
  PathLimits limits;
  limits.max_bounces = params.max_bounces;
  limits.rr_start = params.rr_start;
  limits.safety_cap = params.safety_cap;
  return limits;
}

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
    if (params.emitter_guide != 0u) emitter_guide_learn_arrived(p, k);
    add_result(work, depth, contribution.xyz);
    if (params.light_layers != 0u) {
      // Slot 0: the area sample (layer in the low half of path_ray_o.w), 1: the punctual light (high half), 2: the sky.
      uint layers = floatBitsToUint(path_ray_o[p].w);
      add_light_result(work, k == 0u ? (layers & 0xFFFFu) : k == 1u ? (layers >> 16u) : kSkyLightLayer, contribution.xyz);
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
    next_event_estimation(x, origin, throughput, guide, emitter, rng, area, punctual_light, environment, sources);
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
  uint pending = shadows ? 2u : 0u;
  if (directional_texel) path_throughput[sh1_factor_index(p)] = vec4(d.pdf > 0.0 ? sh1_direction_factor(x, d.direction) : vec3(0.0), 0.0);
  if (!(d.pdf > 0.0)) return pending;
  // w: the learning key of the ray's bin (guide.glsl), read back when its hit is shaded.
  uint key = (params.guiding & kGuidingLearn) != 0u ? guide_learning_key(record, guide, d.direction) : kInvalid;
  path_ray_d[p] = vec4(d.direction, uintBitsToFloat(key));
  path_throughput[p] = vec4(throughput * continuation_weight(guide, x, d), d.pdf);  // weight 1 for cosine vertices
  return pending | 1u;
}
