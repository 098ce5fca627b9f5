#version 460
#extension GL_GOOGLE_include_directive : require
// Stage "shade": at each extension ray's hit, path.h's shade_continuation_hit (emission with MIS,
// absorption by back faces, bounce limits, albedo, Russian roulette) or the sky on a miss; then
// next-event estimation and the continuation at the new vertex. Finished paths are regenerated.
// Probe batches (the kProbeMode variant): depth 0 is the ray from the probe, shaded by
// shade_probe_hit, with the hit's albedo kept apart (the reference multiplies the hit's whole E/pi
// estimate by it); the path from the hit is the texel estimator with its depth counted from 1.
// Per-bounce layer passes (params.bounce_flags) shade with bounce_pass.glsl instead.
layout(local_size_x = 64) in;
#include "../include/kernel_prelude.glsl"

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= counters[kCounterRayQueue0 + push.cur]) return;
  uint p = ray_queue[push.cur * params.path_capacity + i];
  vec4 hit = path_hit[p];
  uint tri = floatBitsToUint(hit.y);
  uint work = path_work[p], depth = path_depth[p];
  vec4 tp = path_throughput[p];
  vec3 wi = path_ray_d[p].xyz;
  uvec4 rs = path_rng[p];
  PathSampler rng;
  rng.item_hash = rs.x;
  rng.index = rs.y;
  rng.dimension = rs.z;
  rng.mode = rs.w;

  // Guided learning passes: the ray teaches its vertex's bin what it met (guide.glsl).
  if (!kProbeMode && (params.guiding & kGuidingLearn) != 0u) guide_learn_from_hit(floatBitsToUint(path_ray_d[p].w), tri, hit, wi);

  bool continues = false;
  vec3 throughput = tp.xyz;
  SurfacePoint x;
  uint next_depth = depth + 1u;
  if (!kProbeMode && (params.bounce_flags & kBouncePass) != 0u) {
    BounceHit b = shade_bounce_hit(p, work, depth, hit, wi, tp, rng);
    if (b.queued) {
      path_rng[p] = uvec4(rng.item_hash, rng.index, rng.dimension, rng.mode);
      return;
    }
    continues = b.direct_sample;  // one direct-light sample at the hit, through the same sample_vertex
    x = b.next;
    throughput = b.throughput;
    next_depth = kBounceDirectRay;
  } else if (kProbeMode && depth == 0u) {
    vec3 albedo = vec3(0.0);
    uint met_layer = 0u;  // 1 + the light layer of slot 0's radiance (0: none)
    // A change estimate (params.changed_light_pairs) adds neither sky nor emission: they did not change.
    bool change = params.changed_light_pairs != 0u;
    if (tri == kInvalid) {
      if (!change) {
        add_result(work, 0u, scene_sky_radiance(wi));
        met_layer = kSkyLightLayer + 1u;
      }
    } else {
      ProbeHit h = shade_probe_hit(tri, hit.z, hit.w, wi);
      if (h.radiance != vec3(0.0) && !change) {
        add_result(work, 0u, h.radiance);
        met_layer = emitter_light_layer(tri) + 1u;
      }
      albedo = h.back_face ? vec3(-1.0) : h.albedo;
      continues = h.continues;
      x = h.next;
    }
    uint e = probe_extra_index(work);
    results[e] = albedo.x;
    results[e + 1u] = albedo.y;
    results[e + 2u] = albedo.z;
    results[e + 6u] = float(met_layer);
  } else if (tri == kInvalid) {
    // The change estimate (params.changed_light_pairs, path.h) adds no sky: it did not change.
    if (params.changed_light_pairs == 0u) {
      // With light subpaths from the sky, weighed against the left vertex's connections to them too.
      vec3 sky = throughput * (path_connects(p) ? escaped_radiance_with_subpaths(stored_cos_left(p), stored_eye_subpath_vertex(p), wi, tp.w)
                                                   : escaped_radiance(wi, tp.w));
      add_path_result(p, work, depth, sky);
      add_light_result(work, kSkyLightLayer, sky);
    }
  } else {
    int bounce = kProbeMode ? int(depth) - 1 : int(depth);  // the vertex's bounce as the texel estimator counts it
    // Emitter guiding: the hit's MIS weight reads the density of the mixture its vertex sampled.
    EmitterGuide emitter = kProbeMode ? emitter_guide_none() : emitter_guide_of_path(p);
    // Light subpaths: the emitter hit's weight counts the strategies with more light vertices, and
    // the new vertex's state follows from the left one's (path.h).
    bool subpaths = path_connects(p);
    EyeSubpathVertex eye = eye_subpath_vertex_none();
    vec3 ng = vec3(0.0);
    float emission_extra = 0.0;
    if (subpaths) {
      eye = stored_eye_subpath_vertex(p);
      ng = triangle_geometric_normal(tri);
      emission_extra = light_subpath_emitter_hit_extra(stored_cos_left(p), eye, emitter, tri, ng, hit.x, hit.z, hit.w, wi);
    }
    HitResult h = shade_continuation_hit(tri, hit.x, hit.z, hit.w, wi, tp.w, throughput, bounce, path_limits(), emitter,
                                         emission_extra, rng);
    if (subpaths && h.continues) {
      eye = next_eye_subpath_vertex(eye, stored_cos_left(p), h.next, ng, hit.x, wi, tp.w, bounce == 0);
      path_throughput[eye_subpath_index(p)].xy = vec2(eye.pdf_forward, eye.eye_sum);
    }
    // Only emitters add: a read-modify-write of the result slot per hit cost the H200 14 % of this stage.
    if (h.radiance != vec3(0.0) && params.changed_light_pairs == 0u) {
      add_path_result(p, work, depth, h.radiance);
      add_light_result(work, emitter_light_layer(tri), h.radiance);
    }
    continues = h.continues;
    throughput = h.throughput;
    x = h.next;
  }
  if (continues) {
    path_depth[p] = next_depth;
    uint r = sample_vertex(p, x, throughput, rng);
    path_rng[p] = uvec4(rng.item_hash, rng.index, rng.dimension, rng.mode);
    if (dispatch_vertex_result(p, r)) return;
  }
  regenerate(p);
}
