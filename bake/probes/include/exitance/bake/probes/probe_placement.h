// Light-probe placement (DESIGN §1, §5): a regular grid over the scene bounds, probes at the
// centres of ceil(extent / spacing) cells per axis (two layers straddling a flat axis). A grid point inside
// geometry (most of its test rays hit back faces of single-sided surfaces) or in an occupied SVO
// leaf (closer to a surface than a voxel) is moved to the nearest free candidate within half a
// spacing, or marked invalid; a point in the open (over a quarter of its test rays escape) with no triangle within
// a few spacings (Embree's point query) is skipped (far from all geometry: nothing there for a
// probe to light). Positions and states
// only: the lighting stage fills the coefficients.
#pragma once
#include <cstdint>
#include <string>

#include "exitance/formats/probe_grid.h"
#include "exitance/formats/sparse_voxel_octree.h"
#include "exitance/runtime/embree_scene.h"
#include "exitance/runtime/scene.h"

namespace exitance {

struct ProbePlacementSettings {
  float spacing = 0;                   // scene units; 0 = automatic (largest extent / 12)
  uint64_t max_probes = 1u << 20;      // a finer grid is refused with an error naming the option
  uint32_t test_rays = 64;             // Fibonacci-sphere rays per candidate position
  float inside_backface_fraction = 0.25f;  // more back-face hits than this: inside geometry
  // No triangle within this many spacings (distance to the nearest point of any triangle) and over
  // a quarter of the test rays escape: skipped (0 = never skip).
  float skip_distance_in_spacings = 3.0f;
};

struct ProbePlacement {
  formats::ProbeGrid grid;  // positions and states; coefficients zero
  uint32_t valid = 0, moved = 0, invalid = 0, skipped = 0;
  bool automatic_spacing = true;
};

// The automatic spacing for a scene: its largest bounding-box extent / 12, so a room gets about a
// dozen probes per side (Unity/Godot-like density); 1 for an empty or degenerate scene.
float automatic_probe_spacing(const Scene& scene);

// `svo` may be null (no occupancy test); its occupancy is used only when its leaves are at most a
// quarter spacing wide. Throws std::invalid_argument when the grid would exceed
// settings.max_probes or the spacing is not a positive finite number.
ProbePlacement place_probes(const Scene& scene, const EmbreeScene& embree, const formats::SparseVoxelOctree* svo,
                            const ProbePlacementSettings& settings);

}  // namespace exitance
