// Charts: groups of faces that can be flattened together. Region growing by normal cone over
// manifold, consistently oriented, non-sharp edges; charts that are not topological disks, or too
// big for one LSCM solve, are split in two until they are.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "welded_mesh.h"

namespace exitance::uvgen {

struct Chart {
  std::vector<uint32_t> triangles;  // input triangle indices, ascending
  Point3 normal{0, 0, 1};           // the seed face's normal (every face is within the cone of it)
};

struct SegmentationSettings {
  double cone_degrees = 90;
  double sharp_edge_degrees = 75;
  size_t max_chart_triangles = 20000;
};

// neighbour[3 t + k]: the face across corner k's edge (k → k+1), or -1 when that edge is a seam: a
// boundary, used by more than two faces, shared by faces of opposite orientation, or sharp.
std::vector<int32_t> face_neighbours(const WeldedMesh& mesh, double sharp_edge_degrees);

// Splits charts that are not disks or are too large, keeping the order deterministic. A part is
// grown from each of two far-apart faces (in face hops) over the chart's neighbour links.
class ChartSplitter {
 public:
  ChartSplitter(const WeldedMesh& mesh, const std::vector<int32_t>& neighbour, size_t max_triangles);
  // Appends the chart, or its parts until each is a disk within max_triangles.
  void add(Chart chart, std::vector<Chart>& out);

 private:
  std::vector<Chart> split(const Chart& chart);
  uint32_t farthest_from(uint32_t start);

  const WeldedMesh& mesh_;
  const std::vector<int32_t>& neighbour_;
  size_t max_triangles_;
  std::vector<uint32_t> member_;    // == stamp_: in the chart being split
  std::vector<uint32_t> distance_;  // == walk_: visited by the current walk
  std::vector<uint8_t> label_;      // per face of the chart being split: which part it grew into
  uint32_t stamp_ = 0, walk_ = 0;
};

// Every non-degenerate triangle lands in exactly one chart; degenerate triangles in none. The first
// chart grows from `first_seed` (a non-degenerate face), or from the first face when it is -1; each
// later one from the free face whose normal is farthest from every seed so far.
std::vector<Chart> segment_into_charts(const WeldedMesh& mesh, const std::vector<int32_t>& neighbour,
                                       const SegmentationSettings& settings, ChartSplitter& splitter,
                                       int64_t first_seed = -1);

// First seeds worth trying: the faces whose normals point farthest along +x, -x, +y, -y, +z, -z
// (distinct, non-degenerate). Where the first cone boundaries fall decides whether a ring's charts
// are its top and bottom halves or arches across it. World axes rather than the normals' principal
// axes: on a sphere or a cube those are degenerate, and which basis an eigensolver returns there
// would change with round-off.
std::vector<uint32_t> axis_seed_faces(const WeldedMesh& mesh);

// True when the chart's faces, sharing the welded vertices, form a topological disk: every edge used
// once or twice with opposite orientations, V - E + F = 1 and exactly one boundary loop through
// vertices with one boundary edge in and one out.
bool chart_is_disk(const WeldedMesh& mesh, const std::vector<uint32_t>& triangles);

}  // namespace exitance::uvgen
