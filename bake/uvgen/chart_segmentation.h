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

// Every non-degenerate triangle lands in exactly one chart; degenerate triangles in none.
std::vector<Chart> segment_into_charts(const WeldedMesh& mesh, const SegmentationSettings& settings);

// True when the chart's faces, sharing the welded vertices, form a topological disk: every edge used
// once or twice with opposite orientations, V - E + F = 1 and exactly one boundary loop through
// vertices with one boundary edge in and one out.
bool chart_is_disk(const WeldedMesh& mesh, const std::vector<uint32_t>& triangles);

}  // namespace exitance::uvgen
