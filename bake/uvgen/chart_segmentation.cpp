#include "chart_segmentation.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <numbers>

namespace exitance::uvgen {
namespace {

constexpr int32_t kNoNeighbour = -1;

double dot(const Point3& a, const Point3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
double cos_degrees(double degrees) {
  return std::cos(degrees * std::numbers::pi / 180.0);
}

}  // namespace

std::vector<int32_t> face_neighbours(const WeldedMesh& mesh, double sharp_edge_degrees) {
  struct DirectedEdge {
    uint32_t lo, hi, face;
    uint8_t corner;
    bool forward;  // runs lo → hi
  };
  std::vector<DirectedEdge> edges;
  edges.reserve(mesh.triangle_count() * 3);
  for (uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    if (mesh.degenerate[t]) continue;
    for (uint8_t k = 0; k < 3; ++k) {
      const uint32_t a = mesh.triangles[t][k], b = mesh.triangles[t][(k + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b), t, k, a < b});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const DirectedEdge& x, const DirectedEdge& y) {
    if (x.lo != y.lo) return x.lo < y.lo;
    if (x.hi != y.hi) return x.hi < y.hi;
    if (x.face != y.face) return x.face < y.face;
    return x.corner < y.corner;
  });
  const double cos_sharp = cos_degrees(sharp_edge_degrees);
  std::vector<int32_t> neighbour(mesh.triangle_count() * 3, kNoNeighbour);
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi)
      ++j;
    if (j - i == 2) {
      const DirectedEdge &x = edges[i], &y = edges[i + 1];
      const bool manifold = x.face != y.face && x.forward != y.forward;
      if (manifold && dot(mesh.normals[x.face], mesh.normals[y.face]) >= cos_sharp) {
        neighbour[3 * size_t(x.face) + x.corner] = int32_t(y.face);
        neighbour[3 * size_t(y.face) + y.corner] = int32_t(x.face);
      }
    }
    i = j;
  }
  return neighbour;
}

ChartSplitter::ChartSplitter(const WeldedMesh& mesh, const std::vector<int32_t>& neighbour, size_t max_triangles)
    : mesh_(mesh),
      neighbour_(neighbour),
      max_triangles_(std::max<size_t>(max_triangles, 1)),
      member_(mesh.triangle_count(), 0),
      distance_(mesh.triangle_count(), 0),
      label_(mesh.triangle_count(), 0) {}

void ChartSplitter::add(Chart chart, std::vector<Chart>& out) {
  std::vector<Chart> pending{std::move(chart)};
  while (!pending.empty()) {
    Chart c = std::move(pending.back());
    pending.pop_back();
    if (c.triangles.size() <= 1 || (c.triangles.size() <= max_triangles_ && chart_is_disk(mesh_, c.triangles))) {
      out.push_back(std::move(c));
      continue;
    }
    std::vector<Chart> parts = split(c);
    for (auto it = parts.rbegin(); it != parts.rend(); ++it)
      pending.push_back(std::move(*it));
  }
}

std::vector<Chart> ChartSplitter::split(const Chart& chart) {
  ++stamp_;
  for (uint32_t t : chart.triangles)
    member_[t] = stamp_;
  const uint32_t a = farthest_from(chart.triangles.front());
  const uint32_t b = farthest_from(a);
  for (uint32_t t : chart.triangles) label_[t] = 0;  // 0 none, 1 grown from a, 2 from b
  std::deque<uint32_t> queue{a};
  label_[a] = 1;
  if (b != a) {
    queue.push_back(b);
    label_[b] = 2;
  }
  while (!queue.empty()) {
    const uint32_t t = queue.front();
    queue.pop_front();
    const uint8_t l = label_[t];
    for (int k = 0; k < 3; ++k) {
      const int32_t u = neighbour_[3 * size_t(t) + size_t(k)];
      if (u == kNoNeighbour || member_[size_t(u)] != stamp_) continue;
      uint8_t& lu = label_[size_t(u)];
      if (lu) continue;
      lu = l;
      queue.push_back(uint32_t(u));
    }
  }
  std::vector<Chart> parts(3);
  for (uint32_t t : chart.triangles) parts[label_[t]].triangles.push_back(t);
  parts[1].normal = mesh_.normals[a];
  parts[2].normal = mesh_.normals[b];
  parts[0].normal = chart.normal;
  std::vector<Chart> result;
  for (size_t i : {size_t(1), size_t(2), size_t(0)})
    if (!parts[i].triangles.empty()) result.push_back(std::move(parts[i]));
  if (result.size() == 1) {  // no second seed: split by position in the list instead
    Chart& whole = result.front();
    Chart half;
    half.normal = whole.normal;
    half.triangles.assign(whole.triangles.begin() + long(whole.triangles.size() / 2), whole.triangles.end());
    whole.triangles.resize(whole.triangles.size() / 2);
    result.push_back(std::move(half));
  }
  return result;
}

uint32_t ChartSplitter::farthest_from(uint32_t start) {
  ++walk_;
  std::deque<uint32_t> queue{start};
  distance_[start] = walk_;
  uint32_t last = start;
  while (!queue.empty()) {
    last = queue.front();
    queue.pop_front();
    for (int k = 0; k < 3; ++k) {
      const int32_t u = neighbour_[3 * size_t(last) + size_t(k)];
      if (u == kNoNeighbour || member_[size_t(u)] != stamp_ || distance_[size_t(u)] == walk_) continue;
      distance_[size_t(u)] = walk_;
      queue.push_back(uint32_t(u));
    }
  }
  return last;
}

bool chart_is_disk(const WeldedMesh& mesh, const std::vector<uint32_t>& triangles) {
  struct Edge {
    uint32_t lo, hi;
    bool forward;
  };
  std::vector<Edge> edges;
  std::vector<uint32_t> vertices;
  edges.reserve(triangles.size() * 3);
  vertices.reserve(triangles.size() * 3);
  for (uint32_t t : triangles)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = mesh.triangles[t][size_t(k)], b = mesh.triangles[t][size_t(k + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b), a < b});
      vertices.push_back(a);
    }
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) {
    return x.lo != y.lo ? x.lo < y.lo : (x.hi != y.hi ? x.hi < y.hi : x.forward < y.forward);
  });
  std::sort(vertices.begin(), vertices.end());
  const size_t vertex_count = size_t(std::unique(vertices.begin(), vertices.end()) - vertices.begin());
  std::vector<std::pair<uint32_t, uint32_t>> boundary;  // directed boundary edges (from, to)
  size_t edge_count = 0;
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi)
      ++j;
    if (j - i > 2) return false;
    if (j - i == 2 && edges[i].forward == edges[i + 1].forward) return false;
    if (j - i == 1)
      boundary.push_back(edges[i].forward ? std::pair{edges[i].lo, edges[i].hi} : std::pair{edges[i].hi, edges[i].lo});
    ++edge_count;
    i = j;
  }
  if (int64_t(vertex_count) - int64_t(edge_count) + int64_t(triangles.size()) != 1) return false;
  if (boundary.empty()) return false;
  std::sort(boundary.begin(), boundary.end());
  for (size_t i = 1; i < boundary.size(); ++i)
    if (boundary[i].first == boundary[i - 1].first) return false;  // two boundary edges leave one vertex
  // Walk the loop from the first boundary edge; a disk's single loop visits
  // every boundary edge.
  size_t steps = 0;
  uint32_t at = boundary.front().first;
  do {
    auto it = std::lower_bound(boundary.begin(), boundary.end(), std::pair{at, uint32_t(0)});
    if (it == boundary.end() || it->first != at) return false;
    at = it->second;
    ++steps;
  } while (at != boundary.front().first && steps <= boundary.size());
  return steps == boundary.size();
}

std::vector<uint32_t> axis_seed_faces(const WeldedMesh& mesh) {
  std::vector<uint32_t> seeds;
  for (size_t axis = 0; axis < 3; ++axis) {
    int64_t lowest = -1, highest = -1;
    double low = 2, high = -2;
    for (uint32_t t = 0; t < mesh.triangle_count(); ++t) {
      if (mesh.degenerate[t]) continue;
      const double d = mesh.normals[t][axis];
      if (d > high) high = d, highest = t;
      if (d < low) low = d, lowest = t;
    }
    for (int64_t t : {highest, lowest})
      if (t >= 0 && std::find(seeds.begin(), seeds.end(), uint32_t(t)) == seeds.end()) seeds.push_back(uint32_t(t));
  }
  return seeds;
}

std::vector<Chart> segment_into_charts(const WeldedMesh& mesh, const std::vector<int32_t>& neighbour,
                                       const SegmentationSettings& settings, ChartSplitter& splitter,
                                       int64_t first_seed) {
  const double cos_cone = cos_degrees(settings.cone_degrees);
  std::vector<uint8_t> assigned(mesh.triangle_count(), 0);
  std::vector<Chart> charts;
  std::deque<uint32_t> queue;
  // Seeds: the free face whose normal is farthest from every seed so far (a
  // sphere then gives two caps, not a cap and crescents), for the first charts;
  // after that, the first free face in order, which bounds the cost on meshes
  // with many charts.
  constexpr size_t kFarthestSeedCharts = 128;
  std::vector<double> closest_seed(mesh.triangle_count(), -2);  // max over seeds of dot(normal, seed normal)
  uint32_t next_in_order = 0;
  for (size_t grown = 0;; ++grown) {
    int64_t seed = -1;
    if (grown < kFarthestSeedCharts) {
      double best = 3;
      for (uint32_t t = 0; t < mesh.triangle_count(); ++t)
        if (!mesh.degenerate[t] && !assigned[t] && closest_seed[t] < best) best = closest_seed[t], seed = t;
    } else {
      while (next_in_order < mesh.triangle_count() && (mesh.degenerate[next_in_order] || assigned[next_in_order]))
        ++next_in_order;
      if (next_in_order < mesh.triangle_count()) seed = next_in_order;
    }
    if (grown == 0 && first_seed >= 0) seed = first_seed;
    if (seed < 0) break;
    Chart chart;
    chart.normal = mesh.normals[size_t(seed)];
    if (grown + 1 < kFarthestSeedCharts)
      for (uint32_t t = 0; t < mesh.triangle_count(); ++t)
        closest_seed[t] = std::max(closest_seed[t], dot(mesh.normals[t], chart.normal));
    assigned[size_t(seed)] = 1;
    queue.push_back(uint32_t(seed));
    while (!queue.empty()) {
      const uint32_t t = queue.front();
      queue.pop_front();
      chart.triangles.push_back(t);
      for (int k = 0; k < 3; ++k) {
        const int32_t u = neighbour[3 * size_t(t) + size_t(k)];
        if (u == kNoNeighbour || assigned[size_t(u)] || dot(mesh.normals[size_t(u)], chart.normal) < cos_cone) continue;
        assigned[size_t(u)] = 1;
        queue.push_back(uint32_t(u));
      }
    }
    std::sort(chart.triangles.begin(), chart.triangles.end());
    splitter.add(std::move(chart), charts);
  }
  return charts;
}

}  // namespace exitance::uvgen
