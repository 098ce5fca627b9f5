// Emitter guiding on the wavefront (--emitter-guiding on; docs/lighting-core.md "Emitter guiding on
// the Vulkan backend"): a vertex's record and EmitterGuide from the guide buffer's emitter section
// (gpu_layout.h kEmitterGuide*, at word params.emitter_guide), and the learning of its arrived
// shadow rays into the back tables. The estimator and the learning rule are the CPU reference's
// (path.h next_event_estimation, guided_emitters.h, EmitterGuidingCache::vertex_site and learn);
// EmitterGuidingCache on the host folds the back sums between passes. Included after guide.glsl.

uint emitter_guide_header(uint word) { return guide_words[params.emitter_guide + word]; }

// EmitterGuidingCache::record_of; kGuideNoRecord without the section.
uint emitter_guide_record(vec3 position, vec3 shading_normal) {
  if (params.emitter_guide == 0u) return kGuideNoRecord;
  return guide_grid_record_at(emitter_guide_header(kEmitterGuideLocator), position, shading_normal);
}

// EmitterGuidingCache::vertex: the front tables' strategy at a record.
EmitterGuide emitter_guide_of(uint record) {
  EmitterGuide g = emitter_guide_none();
  if (record == kGuideNoRecord || params.emitter_guide == 0u) return g;
  uint front = emitter_guide_header(kEmitterGuideFront) + record * kEmitterGuideFrontWords;
  uint patches = emitter_guide_header(kEmitterGuidePatches);
  if (patches > 0u) {
    g.guided_probability = uintBitsToFloat(guide_words[front]);
    g.cdf = emitter_guide_header(kEmitterGuideCdf) + record * (patches + 1u);
    g.patch_count = patches;
    g.emitter_patch = emitter_guide_header(kEmitterGuideEmitterPatch);
    g.patch_emitters = emitter_guide_header(kEmitterGuidePatchEmitters);
    g.triangle_emitter = emitter_guide_header(kEmitterGuideTriangleEmitter);
  }
  uint punctual = emitter_guide_header(kEmitterGuidePunctual);
  if (punctual > 0u) {
    g.punctual_guided_probability = uintBitsToFloat(guide_words[front + 1u]);
    g.punctual_cdf = emitter_guide_header(kEmitterGuidePunctualCdf) + record * (punctual + 1u);
    g.punctual_count = punctual;
  }
  return g;
}

// Per path, what its vertex's next-event samples learn and the record whose density weighs the
// continuation's emitter hit (gpu_layout.h: path_throughput [2P + 2p], [2P + 2p + 1]).
uint emitter_learning_index(uint p) { return 2u * params.path_capacity + 2u * p; }

// EmitterGuidingCache::vertex_site at path p's vertex x (a texel sample's): the strategy its
// next-event estimation uses (emitter_guide_none() where it neither learns nor samples a learned
// distribution: the default's code path), and whether its arrived samples learn.
EmitterGuide emitter_guide_site(uint p, SurfacePoint x, out uint record, out bool learns) {
  record = kGuideNoRecord;
  learns = false;
  if (params.emitter_guide == 0u) return emitter_guide_none();
  uint found = emitter_guide_record(x.position, x.shading_normal);
  EmitterGuide g = emitter_guide_of(found);
  bool sampling_learned = emitter_guide_samples_learned(g);
  uint sample_index = params.batch_sample_begin + path_work[p] / params.batch_item_count;
  learns = emitter_vertex_learns(emitter_learning_of_sample(sample_index), found != kGuideNoRecord, sampling_learned);
  if (!learns && !sampling_learned) return emitter_guide_none();
  record = found;
  return g;
}

// The strategy next-event estimation uses at a vertex that does not learn (emitter_guide_site
// without the learning; EmitterGuidingCache::vertex_site with Learning::None): the record's learned
// mixture where it samples one, else the default's.
EmitterGuide emitter_guide_without_learning(vec3 position, vec3 shading_normal) {
  if (params.emitter_guide == 0u) return emitter_guide_none();
  EmitterGuide g = emitter_guide_of(emitter_guide_record(position, shading_normal));
  return emitter_guide_samples_learned(g) ? g : emitter_guide_none();
}

// Keeps the site's record and what next-event estimation reported for the connect stage and the
// continuation's hit.
void emitter_guide_keep(uint p, uint record, bool learns, EmitterLearning sources) {
  uint i = emitter_learning_index(p);
  path_throughput[i] = vec4(uintBitsToFloat(record), uintBitsToFloat(sources.patch_index), sources.value,
                            uintBitsToFloat(sources.punctual_light));
  path_throughput[i + 1u] = vec4(sources.punctual_value, learns ? 1.0 : 0.0, 0.0, 0.0);
}

// The strategy of the vertex path p's continuation left (for the MIS weight of an emitter it hits).
EmitterGuide emitter_guide_of_path(uint p) {
  if (params.emitter_guide == 0u) return emitter_guide_none();
  return emitter_guide_of(floatBitsToUint(path_throughput[emitter_learning_index(p)].x));
}

// EmitterGuidingCache::learn and learn_punctual: fixed-point sums (and the patch's count) into the
// back tables with integer atomics (guide.glsl guide_add_fixed), so they do not depend on order.
uint64_t emitter_guide_fixed(float value) {
  double units = packDouble2x32(uvec2(emitter_guide_header(kEmitterGuideFixedUnits), emitter_guide_header(kEmitterGuideFixedUnits + 1u)));
  return guide_fixed_point(value, uintBitsToFloat(emitter_guide_header(kEmitterGuideFixedCap)), units);
}

void emitter_guide_learn(uint record, uint patch_index, float value) {
  uint patches = emitter_guide_header(kEmitterGuidePatches);
  if (record == kGuideNoRecord || patch_index >= patches || !(value > 0.0)) return;  // NaN never enters
  uint b = emitter_guide_header(kEmitterGuideBack) + (record * patches + patch_index) * kGuideBackWords;
  guide_add_fixed(b, emitter_guide_fixed(value));
  atomicAdd(guide_words[b + 2u], 1u);
}

void emitter_guide_learn_punctual(uint record, uint light, float value) {
  uint punctual = emitter_guide_header(kEmitterGuidePunctual);
  if (record == kGuideNoRecord || light >= punctual || !(value > 0.0)) return;
  guide_add_fixed(emitter_guide_header(kEmitterGuidePunctualBack) + (record * punctual + light) * kEmitterGuidePunctualBackWords,
                  emitter_guide_fixed(value));
}

// EmitterGuidingCache::learn_arrived for the shadow ray in `slot` of path p (0: the area sample, 1:
// the punctual light's), which arrived.
void emitter_guide_learn_arrived(uint p, uint slot) {
  uint i = emitter_learning_index(p);
  vec4 more = path_throughput[i + 1u];
  if (more.y == 0.0) return;
  vec4 kept = path_throughput[i];
  uint record = floatBitsToUint(kept.x);
  if (slot == 0u) emitter_guide_learn(record, floatBitsToUint(kept.y), kept.z);
  else if (slot == 1u) emitter_guide_learn_punctual(record, floatBitsToUint(kept.w), more.x);
}
