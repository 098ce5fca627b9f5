// Voxelization: the scene's triangles → a sparse voxel octree (formats::SparseVoxelOctree) with
// occupancy and a two-sided normal per node. Exitance is left zero (and no Lit flags set): bake's
// exitance stage fills it from the lit texels (fill_svo_exitance, runtime/bundle/texel_exitance.h).
//
// Algorithm (seed 000): conservative triangle/voxel overlap (separating axis test) over each
// triangle's bounding box → one 64-bit key per (leaf voxel, triangle) pair, Morton code in the high
// bits and triangle index in the low bits → parallel sort → runs of equal codes are the leaves,
// whose normal is a 2-means cluster of their triangles' normals → the hierarchy level by level
// from Morton prefixes (parent code = child code >> 3), breadth-first, children contiguous in
// octant order.
#pragma once
#include <cstdint>

#include "exitance/formats/sparse_voxel_octree.h"
#include "exitance/runtime/scene.h"

namespace exitance {

constexpr uint32_t kSvoMinBuildDepth = 1;
constexpr uint32_t kSvoMaxBuildDepth = 12;  // 4096³ leaves; also keeps 3·depth + triangle bits within 64

struct SvoBuildSettings {
  uint32_t depth = 8;  // leaf level: 2^depth leaves per axis, kSvoMinBuildDepth..kSvoMaxBuildDepth
};

// Seconds per phase and sizes of one build.
struct SvoBuildStatistics {
  double bounds_seconds = 0;     // scene bounds and the cube
  double voxelize_seconds = 0;   // triangle/voxel overlap tests and key emission
  double sort_seconds = 0;       // parallel sort of the keys
  double leaves_seconds = 0;     // dedupe into leaves and the leaf normals
  double hierarchy_seconds = 0;  // internal levels, links and their normals
  double total_seconds = 0;
  uint64_t triangles_voxelized = 0;
  uint64_t triangles_skipped = 0;  // degenerate (zero area) or non-finite
  uint64_t triangle_voxel_pairs = 0;
  uint64_t leaves = 0;
  uint64_t nodes = 0;
  double bytes_per_node = 0;  // sizeof(SvoNode) = 28
  uint64_t total_bytes = 0;   // nodes + level_begin, as held in memory / svo.bin's arrays
};

// What the bake's voxelize stage hands on: the octree (exitance filled later) and its build figures.
struct VoxelizedScene {
  formats::SparseVoxelOctree svo;
  SvoBuildStatistics statistics;
};

// Depth whose leaves are about 4 lightmap texels wide (leaf edge ≈ 4 / texel_density) over the
// scene's largest extent: ceil(log2(extent / leaf)), clamped to [1, 12]. 1 for an empty scene.
// Throws std::invalid_argument when texel_density is not a positive finite number.
uint32_t default_svo_depth(const Scene& scene, float texel_density);

// `--voxel-resolution R` → depth log2(R). Throws std::invalid_argument with a one-line message
// unless R is a power of two in [2, 4096].
uint32_t svo_depth_from_resolution(uint32_t resolution);

// The cube's edge is the scene's largest extent plus at least one leaf of padding on each side
// (depth 1: a quarter leaf); the scene sits a quarter leaf off the cube's centre so that its bounds
// and a flat scene's plane fall inside leaves rather than on the faces between two (which would
// double the voxels of the outer walls). Where the float origin cannot sit exactly (geometry far
// from the origin) the cube grows by the rounding, so the scene always fits. Triangles with zero
// area or non-finite vertices are skipped (import removes them; this is a safety net). A scene
// with no usable triangle gives an empty octree: no nodes, size 0, level_begin all zero (depth + 2
// entries), so formats::svo_find_node answers kSvoNoParent everywhere.
// Throws std::invalid_argument for a depth outside [1, 12].
formats::SparseVoxelOctree build_sparse_voxel_octree(const Scene& scene, const SvoBuildSettings& settings,
                                                     SvoBuildStatistics* statistics = nullptr);

}  // namespace exitance
