// Guiding on the wavefront (issue 11; docs/lighting-core.md "Grid guiding on the Vulkan backend",
// "SVO guiding"): the record of a vertex (grid cell or octree bin), its GuideVertex from the front table, and the learning of its
// continuation ray into the back table, over the guide buffer's sections (gpu_layout.h
// kBindingGuide). The estimator and the learning target are the CPU reference's (path.h,
// common/guide_learning.h); fold_guide.comp folds the back sums between passes with the CPU cache's
// fold (common/guide_fold.h).
#include "exitance/common/guide_learning.h"
#include "exitance/common/guiding_auto_strategy.h"

float guide_float(uint word) { return uintBitsToFloat(guide_words[word]); }

// kGuideLocatorGrid: GridGuidingCache::record_of (cell_index: NaN and below the origin go to cell 0),
// over the grid locator's words from `base` (grid guiding's locator section, or emitter guiding's).
uint guide_grid_record_at(uint base, vec3 position, vec3 shading_normal) {
  vec3 lo = vec3(guide_float(base), guide_float(base + 1u), guide_float(base + 2u));
  float cell = guide_float(base + 3u);
  ivec3 dims = ivec3(guide_words[base + 4u], guide_words[base + 5u], guide_words[base + 6u]);
  ivec3 c;
  for (int a = 0; a < 3; ++a) {
    float f = (position[a] - lo[a]) / cell;
    c[a] = f >= 0.0 ? min(int(min(f, 1e9)), dims[a] - 1) : 0;
  }
  uint cell_index = uint((c.z * dims.y + c.y) * dims.x + c.x);
  return guide_words[base + kGuideGridWords + cell_index * kGuideNormalClasses + guide_normal_class(shading_normal)];
}
uint guide_grid_record(vec3 position, vec3 shading_normal) {
  return guide_grid_record_at(guide_words[kGuideLocatorOffset], position, shading_normal);
}

// kGuideLocatorSvo: SvoGuidingFields::node_of (formats::svo_find_node's descent: the deepest node
// whose cube holds the point) and record_of; in counting passes the vertex adds 1 to its (node,
// class) count in the back section, for the next rebuild's PARTITION-S bins.
uint guide_svo_record(vec3 position, vec3 shading_normal) {
  uint base = guide_words[kGuideLocatorOffset];
  vec3 origin = vec3(guide_float(base), guide_float(base + 1u), guide_float(base + 2u));
  float size = guide_float(base + 3u);
  uint depth = guide_words[base + 4u];
  uint nodes = guide_words[base + 5u];
  vec3 local = (position - origin) / size;
  // Outside the cube (NaN included): no node, cosine sampling.
  if (!(all(greaterThanEqual(local, vec3(0.0))) && all(lessThanEqual(local, vec3(1.0))))) return kGuideNoRecord;
  uint links = base + kGuideSvoWords;
  uint node = 0u;
  for (uint level = 0u; level < depth; ++level) {
    uint cells = 2u << level;  // per axis at level + 1
    uvec3 cell = min(uvec3(local * float(cells)), uvec3(cells - 1u));
    uint octant = (cell.x & 1u) | ((cell.y & 1u) << 1u) | ((cell.z & 1u) << 2u);
    uint mask = guide_words[links + 2u * node + 1u] & 0xFFu;
    if ((mask & (1u << octant)) == 0u) break;
    node = guide_words[links + 2u * node] + uint(bitCount(mask & ((1u << octant) - 1u)));
  }
  uint normal_class = guide_normal_class(shading_normal);
  if ((params.guiding & kGuidingCount) != 0u)
    atomicAdd(guide_words[guide_words[kGuideBackOffset] + node * kGuideNormalClasses + normal_class], 1u);
  uint bin = guide_words[links + 2u * nodes + node];
  if (bin == kGuideNoRecord) return kGuideNoRecord;
  return guide_words[links + 3u * nodes + bin * kGuideNormalClasses + normal_class];
}

// The record of a surface point, or kGuideNoRecord (cosine sampling, nothing learned): one locator
// per kind, the rest of the buffer shared by all kinds.
uint guide_record(vec3 position, vec3 shading_normal) {
  uint kind = guide_words[kGuideLocatorKind];
  if (kind == kGuideLocatorGrid) return guide_grid_record(position, shading_normal);
  if (kind == kGuideLocatorSvo) return guide_svo_record(position, shading_normal);
  return kGuideNoRecord;
}

// GridGuidingCache::vertex: the front table's strategy at a record.
GuideVertex guide_vertex_of(uint record) {
  GuideVertex g = guide_vertex_cosine();
  if (record == kGuideNoRecord) return g;
  uint f = guide_words[kGuideFrontOffset] + record * kGuideFrontWords;
  g.guided_probability = guide_float(f);
  g.normal_class = guide_words[f + 2u];
  g.cdf = guide_words[kGuideCdfOffset] + record * (kGuideBins + 1u);
  return g;
}

// GridGuidingCache::expected_cosine_radiance: Lbar of the front table (0 without a record).
float guide_expected_cosine(uint record) {
  if (record == kGuideNoRecord) return 0.0;
  return guide_float(guide_words[kGuideFrontOffset] + record * kGuideFrontWords + 1u);
}

// What a continuation of `record` in `direction` learns into: record * kGuideBins + bin, kept with the
// ray (path_ray_d.w bits) until its hit is shaded; kInvalid when it learns nothing (the CPU's test).
uint guide_learning_key(uint record, GuideVertex g, vec3 direction) {
  if (record == kGuideNoRecord) return kInvalid;
  vec3 local = guide_to_class_local(g.normal_class, direction);
  if (!(local.z > 0.0)) return kInvalid;
  return record * kGuideBins + guide_bin_of_local(local);
}

// A 64-bit fixed-point sum at words (lo, hi) from `word`: the low word's add, then the high word's
// with the carry of the low one. Integers, so the sums do not depend on the order of the adds.
void guide_add_fixed(uint word, uint64_t units_sum) {
  uint lo = uint(units_sum & 0xFFFFFFFFul);
  uint hi = uint(units_sum >> 32);
  uint old = atomicAdd(guide_words[word], lo);
  if (old + lo < old) hi += 1u;  // the low word wrapped
  if (hi != 0u) atomicAdd(guide_words[word + 1u], hi);
}

// GridGuidingCache::learn: one target into the back table, a 64-bit fixed-point sum as two words
// with the carry of the low word's add, and a count: integers, so the sums do not depend on order.
void guide_learn(uint key, float target) {
  if (key == kInvalid || !(target >= 0.0)) return;  // NaN never enters
  double units = packDouble2x32(uvec2(guide_words[kGuideFixedUnits], guide_words[kGuideFixedUnits + 1u]));
  uint64_t units_sum = guide_fixed_point(target, guide_float(kGuideFixedCap), units);
  uint b = guide_words[kGuideBackOffset] + key * kGuideBackWords;
  guide_add_fixed(b, units_sum);
  atomicAdd(guide_words[b + 2u], 1u);
}

// The continuation ray with learning key `key` met triangle `tri` at `hit` (kInvalid: escaped).
void guide_learn_from_hit(uint key, uint tri, vec4 hit, vec3 wi) {
  if (key == kInvalid) return;
  GuideLearningHit h = tri == kInvalid ? guide_learning_escape(wi) : guide_learning_hit(tri, hit.z, hit.w, wi);
  float expected = h.reads_expectation ? guide_expected_cosine(guide_record(h.y.position, h.y.shading_normal)) : 0.0;
  guide_learn(key, guide_learning_target(h, expected));
}

// --guiding auto (gpu_layout.h kGuidingAuto): a texel's strategy word, and whether work item w (a
// texel sample of this batch) is guided.
uint auto_texel_word(uint texel) { return guide_words[guide_words[kGuideAutoTexels] + texel]; }

bool auto_work_guided(uint w) {
  uint n = params.batch_item_count;
  uint texel = batch_items[params.batch_item_offset + w % n];
  return auto_sample_guided(auto_texel_word(texel), params.batch_sample_begin + w / n, guide_words[kGuideAutoPilot]);
}
