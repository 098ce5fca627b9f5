// SVO path guiding (seed 000, chapters 4-5; issue 11): guiding fields built on the fly from radiant
// exitance stored in the bake's sparse voxel octree, sampled by the path tracer as one component of
// a one-sample mixture with cosine sampling (path.h's GuideVertex, as grid guiding is).
//
// Choices (docs/lighting-core.md, "SVO guiding"):
//  - Exitance: a private copy of the octree whose exitance this class owns (never svo.bin's
//    published values), filled from the bake's running lightmap estimate as fill_svo_exitance does
//    (M = pi (Le + albedo E/pi) per texel, area-weighted, sequential double sums: deterministic),
//    published by REPLACEMENT: the running estimate is already the mean of every sample so far, so
//    blending it with an older (noisier) mean would only weight early samples twice.
//  - Bins (PARTITION-S, seed Alg. 4): path vertices are counted per (node, normal class) during the
//    passes (integer atomics); at a rebuild each node's subtree count is summed bottom-up, and a node
//    at level >= l_min is a bin when its subtree holds >= c_ray vertices per sample per texel (the
//    thesis's c_ray counts one 1-spp frame, so the threshold scales with the samples counted) or it
//    is at level l_min. A vertex's bin is its first marked ancestor (or itself); none: cosine only.
//  - Fields: per (bin, normal class) with counted vertices and a texel of that class in the bin, a
//    capture origin = one of those texels (hashed pick, re-picked per rebuild); rays_per_bin rays
//    per hemisphere bin of guided_direction.h (stratified, jittered per rebuild), averaged; at hit distance r the octree is
//    read at the level whose voxel edge matches the footprint diameter 2 r tan(theta) of the cone
//    of the bin's mean solid angle (svo_guide_cone_level), on the side facing the ray; the hit
//    triangle's own emission is kept when larger (emitters without texels); misses read the sky.
//    Luminance per bin, a [1 2 1]^2 / 16 blur on the square, a uniform floor, CDF. Equal
//    cosine-mass bins make the sampled density L x cos (the product with a fixed normal's cosine).
//  - Schedule (the caller's): the first pass unguided (no counts yet), rebuilds after the passes
//    that reach 1, 2, 4, 8, ... samples per texel.
//
// DEVICE CONTRACT (a GLSL port reads exactly these flat arrays; nothing else):
//   node_links():   2 uint per octree node (breadth-first, as svo.bin): [0] first_child,
//                   [1] child_mask (bits 0-7) | level << 8. Descent from the root as svo_find_node:
//                   at level l the octant of p is bit a = floor(local_a * 2^(l+1)) & 1 per axis,
//                   local = (p - origin) / size; stop when the child bit is clear or l = depth.
//   node_bin():     1 uint per node: the bin of a vertex whose descent ends at that node, or kNoBin.
//   record_index(): kGuideNormalClasses uint per bin: the record of (bin, class), or kNoRecord.
//   record_front(): 2 per record: [0] guided probability (float), [1] normal class (uint as float bits).
//   cdf():          (kGuideBins + 1) floats per record, cdf[0] = 0, cdf[kGuideBins] = 1, as
//                   guided_direction.h's guide_cdf_at reads it.
//   origin(), size(), depth(): the cube. A vertex at p with shading normal n: node = descend(p),
//   bin = node_bin[node], record = bin == kNoBin ? kNoRecord : record_index[bin * 6 + class(n)];
//   kNoRecord or probability 0: cosine only. Counting (for the next rebuild) adds 1 to
//   counts[node * 6 + class] with an integer atomic.
#pragma once
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "exitance/common/guided_direction.h"
#include "exitance/formats/sparse_voxel_octree.h"
#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/integrator_settings.h"
#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

class SvoExitanceCache;

struct SvoGuidingConfig {
  float mix = 0.5f;         // guided component's probability at a guided vertex
  double c_ray = 512;       // vertices per sample per texel that make a node a bin
  int l_min_below_depth = 3;  // l_min = max(0, depth - this)
  // Rays per hemisphere bin of a field (a stratified k x k grid in the bin's square, k = floor(sqrt)):
  // the thesis's 1 aliases small openings (a 5 cm gap is a fifth of a bin 3 m away).
  uint32_t rays_per_bin = 1;
  // Whether fields hold emitted radiance too (the thesis) or only reflected radiance: next-event
  // estimation already samples emitters, and guided rays spent on them only split its MIS weight.
  bool emitted = true;
};
// The configuration an integrator's settings ask for (guiding_mix, guiding_svo_*), for every backend.
SvoGuidingConfig svo_guiding_config(const IntegratorSettings& settings);

// The octree level whose voxel edge (size / 2^level) is the diameter of the footprint at distance
// r of a cone of solid angle `solid_angle`: the cone's plane half-angle theta solves
// solid_angle = 2 pi (1 - cos theta), footprint radius R = r tan(theta), level =
// floor(log2(size / (2 R))) clamped to [0, depth]: the finest voxel whose edge is at least the
// footprint's diameter, so the read averages over the whole footprint (as a cone march would). Seed 000's public code passes the solid angle
// 4 pi / N^2 where this plane angle belongs (R = 4 r / N); for a hemisphere bin of 2 pi / N^2,
// theta ~ sqrt(2) / N, about a third of that.
double svo_guide_cone_half_angle(double solid_angle);
uint32_t svo_guide_cone_level(double solid_angle, double distance, double octree_size, uint32_t depth);

// What the field build asks of a ray cast: the nearest hit from origin along a unit direction.
struct GuideRayHit {
  bool found = false;
  float distance = 0;
  uint32_t triangle = 0;
};
using GuideRayCast = std::function<GuideRayHit(Vec3 origin, Vec3 direction)>;

class SvoGuidingFields {
 public:
  static constexpr uint32_t kNoRecord = 0xFFFFFFFFu;
  static constexpr uint32_t kNoBin = 0xFFFFFFFFu;
  static constexpr uint32_t kNoNode = 0xFFFFFFFFu;
  static constexpr float kUniformFloor = 0.05f;

  // `octree`: the bake's SVO (copied; its exitance seeds the guiding cache when it holds any).
  // `cast`: the ray cast of the field build; empty: the scene's core BVH (core/bvh4_closest_hit.h).
  SvoGuidingFields(const LightingScene& scene, const formats::SparseVoxelOctree& octree, const TexelGBuffer& gbuffer,
                   const SvoGuidingConfig& config, GuideRayCast cast = {});
  ~SvoGuidingFields();

  // The node a vertex at `position` descends to (kNoNode outside the cube).
  uint32_t node_of(Vec3 position) const;
  // The record of a vertex at `node` with shading normal `n`, kNoRecord when it has none.
  uint32_t record_of(uint32_t node, Vec3 shading_normal) const;
  uint32_t record_of(Vec3 position, Vec3 shading_normal) const { return record_of(node_of(position), shading_normal); }
  // The strategy at a vertex of record `record` (cosine only for kNoRecord).
  GuideVertex vertex(uint32_t record) const;
  // Counts one path vertex at `node` for the next rebuild's bins. Thread-safe, integer.
  void count(uint32_t node, Vec3 shading_normal);
  // Adds counts made elsewhere (a device's integer atomics): kGuideNormalClasses per node, as count().
  void import_counts(const uint32_t* counts, size_t words);
  // Whether the octree's exitance was given (an earlier bake or refresh): fields can be built
  // before the first pass, with bins from the texels' positions.
  bool seeded() const { return seeded_; }

  // Between passes: the guiding exitance from `estimate` (the running lightmap of `gbuffer`), bins
  // from the counts since the last rebuild over `samples_counted` samples per texel (0: one count
  // per texel, for a seeded start), then every record's field. Deterministic per `seed`.
  void rebuild(const LightmapEstimate* estimate, double samples_counted, uint64_t seed);

  uint32_t bin_count() const { return bins_; }
  uint32_t record_count() const { return uint32_t(record_bin_.size()); }
  uint32_t rebuilds() const { return rebuilds_; }
  static size_t bytes_per_record();
  size_t memory_bytes() const;

  // The device contract's arrays (see the header comment).
  const std::vector<uint32_t>& node_links() const { return node_links_; }
  const std::vector<uint32_t>& node_bin() const { return node_bin_; }
  const std::vector<uint32_t>& record_index() const { return record_index_; }
  const std::vector<float>& record_front() const { return record_front_; }
  const std::vector<float>& cdf() const { return cdf_; }
  std::array<float, 3> origin() const { return octree_.origin; }
  float size() const { return octree_.size; }
  uint32_t depth() const { return octree_.depth; }

  // Plots and tests: a record's field (kGuideBins luminances before the floor), its capture
  // origin, its bin's node and normal class.
  const float* field(uint32_t record) const { return &field_[size_t(record) * kGuideBins]; }
  Vec3 capture_origin(uint32_t record) const { return record_origin_[record]; }
  uint32_t record_class(uint32_t record) const { return record_class_[record]; }
  uint32_t bin_node(uint32_t bin) const { return bin_node_[bin]; }
  uint32_t record_bin(uint32_t record) const { return record_bin_[record]; }

 private:
  void fill_exitance(const LightmapEstimate& estimate);
  void partition(double samples_counted);
  void build_records(uint64_t seed);
  void build_field(uint32_t record, uint64_t seed);
  float radiance_along(Vec3 origin, Vec3 direction) const;

  const LightingScene& scene_;
  const TexelGBuffer& gbuffer_;
  SvoGuidingConfig config_;
  GuideRayCast cast_;
  formats::SparseVoxelOctree octree_;  // private copy: the guiding exitance lives in its nodes
  std::unique_ptr<SvoExitanceCache> exitance_;
  std::vector<Vec3> node_normals_;
  bool seeded_ = false;
  uint32_t rebuilds_ = 0;
  uint32_t l_min_ = 0;
  uint32_t bins_ = 0;
  std::unique_ptr<std::atomic<uint32_t>[]> counts_;  // per node * kGuideNormalClasses
  std::vector<uint32_t> node_links_, node_bin_, bin_node_, record_index_, record_bin_, record_class_;
  std::vector<Vec3> record_origin_, record_origin_normal_;
  std::vector<float> record_front_, cdf_, field_;
  std::vector<uint32_t> texel_node_;  // per texel, its node (texels do not move)
};

}  // namespace exitance
