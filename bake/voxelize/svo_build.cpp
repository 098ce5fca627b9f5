// Scene → sparse voxel octree; see svo_build.h for the algorithm and the cube's placement.
#include "exitance/bake/voxelize/svo_build.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "exitance/runtime/float_rounding.h"
#include "morton_code.h"
#include "svo_node_normals.h"
#include "triangle_voxel_overlap.h"

namespace exitance {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Twice the area-weighted normal of triangle t, from its world positions in double.
Double3 world_cross(const Scene& scene, size_t t) {
  const Vec3* p = &scene.positions[t * 3];
  const Double3 a{p[0].x, p[0].y, p[0].z}, b{p[1].x, p[1].y, p[1].z}, c{p[2].x, p[2].y, p[2].z};
  return cross(b - a, c - a);
}

bool triangle_is_usable(const Scene& scene, size_t t) {
  const Vec3* p = &scene.positions[t * 3];
  if (!is_finite(p[0]) || !is_finite(p[1]) || !is_finite(p[2])) return false;
  const double area2 = norm(world_cross(scene, t));
  return area2 > 0 && std::isfinite(area2);
}

struct SceneBounds {
  Double3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
             std::numeric_limits<double>::infinity()};
  Double3 hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
             -std::numeric_limits<double>::infinity()};
  bool empty() const { return !(lo[0] <= hi[0]); }
};

SceneBounds usable_triangle_bounds(const Scene& scene, std::vector<uint8_t>& usable) {
  SceneBounds bounds;
  usable.assign(scene.triangle_count(), 0);
  for (size_t t = 0; t < scene.triangle_count(); ++t) {
    if (!triangle_is_usable(scene, t)) continue;
    usable[t] = 1;
    for (int v = 0; v < 3; ++v)
      for (int k = 0; k < 3; ++k) {
        const double x = scene.positions[t * 3 + size_t(v)][k];
        bounds.lo[size_t(k)] = std::min(bounds.lo[size_t(k)], x);
        bounds.hi[size_t(k)] = std::max(bounds.hi[size_t(k)], x);
      }
  }
  return bounds;
}

// Places the scene in the cube so that its bounds and its centre plane fall inside leaves, not on
// their faces: a face is shared by two leaves, so geometry lying on one (the outer walls, which
// sit on the bounds by definition, or a flat scene's plane) would be voxelized twice over. In grid
// units (leaf = 1, resolution r) the bounds' centre sits at r/2 + 1/4 on every axis and the largest
// extent spans r - 3 leaves: [1.75, r - 1.25], at least one leaf of padding per side. At depth 1
// (r = 2) the extent spans one leaf, [0.75, 1.75]. The origin is rounded down to float and the cube
// grown by whatever that rounding cost, so the scene always fits.
void place_cube(const SceneBounds& bounds, uint32_t depth, formats::SparseVoxelOctree& svo) {
  const double resolution = double(1u << depth);
  double extent = 0;
  for (int k = 0; k < 3; ++k) extent = std::max(extent, bounds.hi[size_t(k)] - bounds.lo[size_t(k)]);
  const double extent_in_leaves = resolution >= 4 ? resolution - 3 : 1;
  const double centre_in_leaves = 0.5 * resolution + 0.25;
  double leaf = extent / extent_in_leaves;
  for (int k = 0; k < 3; ++k)
    svo.origin[size_t(k)] =
        float_at_or_below(0.5 * (bounds.lo[size_t(k)] + bounds.hi[size_t(k)]) - centre_in_leaves * leaf);
  double size = resolution * leaf;
  for (int k = 0; k < 3; ++k)
    size = std::max(size, bounds.hi[size_t(k)] + 0.25 * leaf - double(svo.origin[size_t(k)]));
  svo.size = float_at_or_above(size);
  if (!std::isfinite(svo.size) || !(svo.size > 0))
    throw std::range_error("voxelization: the scene's extent does not fit a float cube");
}

// Keys are (Morton code of the leaf << triangle_bits) | triangle index, so one sort of plain
// uint64 groups the pairs by leaf in Morton order, and by triangle within a leaf (deterministic).
struct KeyLayout {
  uint32_t triangle_bits;
  uint64_t triangle_mask() const { return (uint64_t(1) << triangle_bits) - 1; }
  uint64_t key(uint64_t code, uint32_t triangle) const { return (code << triangle_bits) | triangle; }
  uint64_t code(uint64_t key) const { return key >> triangle_bits; }
  uint32_t triangle(uint64_t key) const { return uint32_t(key & triangle_mask()); }
};

// Per triangle: its normal and the area its normal stands for in a leaf, in leaf units. The
// triangle's area is clamped to sqrt(2), the largest plane cross-section of a unit cube but for
// the hexagon's 1.299 < sqrt(2): a cheap upper bound of the area inside any one leaf, so a huge
// triangle grazing a leaf does not outweigh the small triangles that fill it.
constexpr double kMaxAreaInLeaf = 1.4142135623730951;

struct VoxelizeOutput {
  std::vector<uint64_t> keys;
  std::vector<WeightedNormal> triangle_normals;
};

VoxelizeOutput voxelize_triangles(const Scene& scene, const std::vector<uint8_t>& usable,
                                  const formats::SparseVoxelOctree& svo, KeyLayout layout) {
  const int resolution = int(1u << svo.depth);
  const double cells_per_unit = double(resolution) / double(svo.size);
  const Double3 origin{svo.origin[0], svo.origin[1], svo.origin[2]};
  VoxelizeOutput out;
  out.triangle_normals.resize(scene.triangle_count(), WeightedNormal{{0, 0, 1}, 0});
  tbb::enumerable_thread_specific<std::vector<uint64_t>> keys_per_thread;

  tbb::parallel_for(tbb::blocked_range<size_t>(0, scene.triangle_count(), 512), [&](const tbb::blocked_range<size_t>& range) {
    std::vector<uint64_t>& keys = keys_per_thread.local();
    for (size_t t = range.begin(); t != range.end(); ++t) {
      if (!usable[t]) continue;
      Double3 v[3];
      for (int i = 0; i < 3; ++i) {
        const Vec3 p = scene.positions[t * 3 + size_t(i)];
        v[i] = {(p.x - origin[0]) * cells_per_unit, (p.y - origin[1]) * cells_per_unit, (p.z - origin[2]) * cells_per_unit};
      }
      int lo[3], hi[3];
      for (int k = 0; k < 3; ++k) {
        const double min_k = std::min({v[0][k], v[1][k], v[2][k]}), max_k = std::max({v[0][k], v[1][k], v[2][k]});
        lo[k] = std::clamp(int(std::floor(min_k)), 0, resolution - 1);
        hi[k] = std::clamp(int(std::floor(max_k)), 0, resolution - 1);
      }
      const Double3 n = cross(v[1] - v[0], v[2] - v[0]);
      const double n_length = norm(n);
      auto emit = [&](int x, int y, int z) {
        keys.push_back(layout.key(morton::encode(uint32_t(x), uint32_t(y), uint32_t(z)), uint32_t(t)));
      };
      if (!(n_length > 0)) {
        // Far below a leaf (its area underflows in grid units): its direction comes from the world
        // positions (non-zero, the triangle is usable), its weight is negligible, and the few cells
        // of its bounding box are conservative.
        const Double3 world = world_cross(scene, t);
        const double world_length = norm(world);
        out.triangle_normals[t] = {{world[0] / world_length, world[1] / world_length, world[2] / world_length}, 1e-300};
        for (int x = lo[0]; x <= hi[0]; ++x)
          for (int y = lo[1]; y <= hi[1]; ++y)
            for (int z = lo[2]; z <= hi[2]; ++z) emit(x, y, z);
        continue;
      }
      out.triangle_normals[t] = {{n[0] / n_length, n[1] / n_length, n[2] / n_length},
                                 std::min(0.5 * n_length, kMaxAreaInLeaf)};
      if (lo[0] == hi[0] && lo[1] == hi[1] && lo[2] == hi[2]) {  // inside one leaf: no test needed
        emit(lo[0], lo[1], lo[2]);
        continue;
      }
      const TriangleVoxelOverlap overlap(v[0], v[1], v[2]);
      // Walk the columns along the normal's dominant axis w: a column is skipped unless the
      // triangle's projection along w reaches it, and within a column only the cells the plane
      // passes through are tested. Work is proportional to the triangle's area, not its box volume.
      const int w = std::fabs(n[0]) >= std::fabs(n[1]) ? (std::fabs(n[0]) >= std::fabs(n[2]) ? 0 : 2)
                                                        : (std::fabs(n[1]) >= std::fabs(n[2]) ? 1 : 2);
      const int u = (w + 1) % 3, s = (w + 2) % 3;
      const double plane = dot(n, v[0]);
      const double du = -n[u] / n[w], ds = -n[s] / n[w];
      constexpr double kColumnSlack = 1e-6;  // candidates only; the exact test below decides
      for (int cu = lo[u]; cu <= hi[u]; ++cu)
        for (int cs = lo[s]; cs <= hi[s]; ++cs) {
          if (!overlap.projection_overlaps(w, cu, cs)) continue;
          const double base = (plane - n[u] * cu - n[s] * cs) / n[w];
          const double w_min = base + std::min(0.0, du) + std::min(0.0, ds) - kColumnSlack;
          const double w_max = base + std::max(0.0, du) + std::max(0.0, ds) + kColumnSlack;
          const int first = std::max(lo[w], int(std::floor(std::max(w_min, -1.0))));
          const int last = std::min(hi[w], int(std::floor(std::min(w_max, double(resolution)))));
          for (int cw = first; cw <= last; ++cw) {
            int cell[3];
            cell[w] = cw, cell[u] = cu, cell[s] = cs;
            const Double3 corner{double(cell[0]), double(cell[1]), double(cell[2])};
            if (overlap.plane_overlaps(corner) && overlap.projection_overlaps(u, corner[s], corner[w]) &&
                overlap.projection_overlaps(s, corner[w], corner[u]))
              emit(cell[0], cell[1], cell[2]);
          }
        }
    }
  });

  size_t total = 0;
  std::vector<std::pair<std::vector<uint64_t>*, size_t>> parts;  // (keys, offset in the joined array)
  for (std::vector<uint64_t>& keys : keys_per_thread) parts.push_back({&keys, total}), total += keys.size();
  out.keys.resize(total);
  tbb::parallel_for(size_t(0), parts.size(), [&](size_t i) {
    std::copy(parts[i].first->begin(), parts[i].first->end(), out.keys.begin() + std::ptrdiff_t(parts[i].second));
  });
  return out;
}

struct Leaves {
  std::vector<uint64_t> codes;
  std::vector<WeightedNormal> normals;
};

// Runs of equal Morton codes in the sorted keys are the leaves; each leaf's normal is the 2-means
// dominant normal of its triangles.
Leaves dedupe_into_leaves(const std::vector<uint64_t>& sorted_keys, const std::vector<WeightedNormal>& triangle_normals,
                          KeyLayout layout) {
  std::vector<uint32_t> run_begin;
  run_begin.reserve(sorted_keys.size() / 2 + 1);
  for (size_t i = 0; i < sorted_keys.size(); ++i)
    if (i == 0 || layout.code(sorted_keys[i]) != layout.code(sorted_keys[i - 1])) run_begin.push_back(uint32_t(i));
  run_begin.push_back(uint32_t(sorted_keys.size()));
  const size_t leaf_count = run_begin.size() - 1;
  Leaves leaves;
  leaves.codes.resize(leaf_count);
  leaves.normals.resize(leaf_count);
  tbb::enumerable_thread_specific<std::vector<WeightedNormal>> samples_per_thread;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, leaf_count, 4096), [&](const tbb::blocked_range<size_t>& range) {
    std::vector<WeightedNormal>& samples = samples_per_thread.local();
    for (size_t leaf = range.begin(); leaf != range.end(); ++leaf) {
      const uint32_t begin = run_begin[leaf], end = run_begin[leaf + 1];
      leaves.codes[leaf] = layout.code(sorted_keys[begin]);
      const WeightedNormal& first = triangle_normals[layout.triangle(sorted_keys[begin])];
      if (end - begin == 1) {  // most leaves: one triangle, nothing to cluster
        leaves.normals[leaf] = first;
        continue;
      }
      double weight = 0;
      bool coplanar = true;  // e.g. the two triangles of a quad: clustering would return `first`
      samples.clear();
      for (uint32_t i = begin; i < end; ++i) {
        samples.push_back(triangle_normals[layout.triangle(sorted_keys[i])]);
        weight += samples.back().weight;
        coplanar = coplanar && dot(samples.back().normal, first.normal) > 1 - 1e-9;
      }
      leaves.normals[leaf] = {coplanar ? first.normal : two_means_dominant_normal(samples.data(), samples.size()), weight};
    }
  });
  return leaves;
}

uint32_t encode_normal(const Double3& n) {
  return formats::encode_octahedral_normal({float(n[0]), float(n[1]), float(n[2])});
}

// Levels depth-1 .. 0 from Morton prefixes (parent code = child code >> 3). Sorted child codes
// give sorted, contiguous parent runs, so breadth-first order with children contiguous in octant
// order falls out of concatenating the levels.
void build_hierarchy(Leaves leaves, formats::SparseVoxelOctree& svo) {
  const uint32_t depth = svo.depth;
  std::vector<std::vector<uint64_t>> codes(depth + 1);
  codes[depth] = std::move(leaves.codes);
  for (uint32_t level = depth; level >= 1; --level) {
    const std::vector<uint64_t>& children = codes[level];
    std::vector<uint64_t>& parents = codes[level - 1];
    parents.reserve(children.size() / 2 + 1);
    for (size_t i = 0; i < children.size(); ++i)
      if (i == 0 || (children[i] >> 3) != (children[i - 1] >> 3)) parents.push_back(children[i] >> 3);
  }
  svo.level_begin.assign(depth + 2, 0);
  for (uint32_t level = 0; level <= depth; ++level)
    svo.level_begin[level + 1] = svo.level_begin[level] + uint32_t(codes[level].size());
  svo.nodes.resize(svo.level_begin[depth + 1]);

  for (uint32_t level = 0; level <= depth; ++level) {
    tbb::parallel_for(size_t(svo.level_begin[level]), size_t(svo.level_begin[level + 1]), [&](size_t i) {
      formats::SvoNode& node = svo.nodes[i];
      node = formats::SvoNode{};
      node.level = uint8_t(level);
      if (level == depth) node.flags = formats::kSvoLeaf;
    });
  }
  // Links, one level of parents at a time: walking the (sorted) children, a new parent starts
  // wherever the prefix changes.
  for (uint32_t level = 0; level < depth; ++level) {
    const uint32_t begin = svo.level_begin[level];
    const std::vector<uint64_t>& children = codes[level + 1];
    const uint32_t child_begin = svo.level_begin[level + 1];
    uint32_t parent = begin;
    for (size_t i = 0; i < children.size(); ++i) {
      if (i > 0 && (children[i] >> 3) != (children[i - 1] >> 3)) ++parent;
      formats::SvoNode& p = svo.nodes[parent];
      if (p.child_mask == 0) p.first_child = child_begin + uint32_t(i);
      p.child_mask |= uint8_t(1u << (children[i] & 7u));
      svo.nodes[child_begin + i].parent = parent;
    }
  }

  // Normals bottom-up, holding the weighted normals of one level of children at a time.
  std::vector<WeightedNormal> child_normals = std::move(leaves.normals), parent_normals;
  const uint32_t leaf_begin = svo.level_begin[depth];
  tbb::parallel_for(size_t(0), child_normals.size(), [&](size_t i) {
    svo.nodes[leaf_begin + i].normal_oct = encode_normal(child_normals[i].normal);
  });
  for (uint32_t level = depth; level-- > 0;) {
    const uint32_t begin = svo.level_begin[level], child_begin = svo.level_begin[level + 1];
    parent_normals.resize(svo.level_begin[level + 1] - begin);
    tbb::parallel_for(size_t(0), parent_normals.size(), [&](size_t i) {
      formats::SvoNode& node = svo.nodes[begin + i];
      const uint32_t child_count = uint32_t(std::popcount(uint32_t(node.child_mask)));
      const WeightedNormal* children = &child_normals[node.first_child - child_begin];
      double weight = 0;
      for (uint32_t c = 0; c < child_count; ++c) weight += children[c].weight;
      parent_normals[i] = {aligned_average_normal(children, child_count), weight};
      node.normal_oct = encode_normal(parent_normals[i].normal);
    });
    std::swap(child_normals, parent_normals);
  }
}

}  // namespace

uint32_t default_svo_depth(const Scene& scene, float texel_density) {
  if (!(texel_density > 0) || !std::isfinite(texel_density))
    throw std::invalid_argument("voxelization: texel density must be a positive number, got " +
                                std::to_string(texel_density));
  std::vector<uint8_t> usable;
  const SceneBounds bounds = usable_triangle_bounds(scene, usable);
  if (bounds.empty()) return kSvoMinBuildDepth;
  double extent = 0;
  for (int k = 0; k < 3; ++k) extent = std::max(extent, bounds.hi[size_t(k)] - bounds.lo[size_t(k)]);
  const double leaf = 4.0 / double(texel_density);
  const double depth = std::ceil(std::log2(extent / leaf));
  if (!(depth >= kSvoMinBuildDepth)) return kSvoMinBuildDepth;  // also catches NaN
  return uint32_t(std::min(depth, double(kSvoMaxBuildDepth)));
}

uint32_t svo_depth_from_resolution(uint32_t resolution) {
  if (resolution < 2 || resolution > (1u << kSvoMaxBuildDepth) || !std::has_single_bit(resolution))
    throw std::invalid_argument("--voxel-resolution must be a power of two from 2 to 4096, got " +
                                std::to_string(resolution));
  return uint32_t(std::countr_zero(resolution));
}

formats::SparseVoxelOctree build_sparse_voxel_octree(const Scene& scene, const SvoBuildSettings& settings,
                                                     SvoBuildStatistics* statistics) {
  if (settings.depth < kSvoMinBuildDepth || settings.depth > kSvoMaxBuildDepth)
    throw std::invalid_argument("voxelization: octree depth must be from 1 to 12, got " + std::to_string(settings.depth));
  const KeyLayout layout{64 - 3 * settings.depth};
  if (scene.triangle_count() > layout.triangle_mask())
    throw std::length_error("voxelization: " + std::to_string(scene.triangle_count()) +
                            " triangles do not fit the sort keys at depth " + std::to_string(settings.depth));
  SvoBuildStatistics stats;
  const Clock::time_point start = Clock::now();

  formats::SparseVoxelOctree svo;
  svo.depth = settings.depth;
  std::vector<uint8_t> usable;
  const SceneBounds bounds = usable_triangle_bounds(scene, usable);
  stats.triangles_voxelized = uint64_t(std::count(usable.begin(), usable.end(), uint8_t(1)));
  stats.triangles_skipped = scene.triangle_count() - stats.triangles_voxelized;
  if (bounds.empty()) {
    svo.level_begin.assign(svo.depth + 2, 0);
  } else {
    place_cube(bounds, svo.depth, svo);
    stats.bounds_seconds = seconds_since(start);

    Clock::time_point phase = Clock::now();
    VoxelizeOutput voxelized = voxelize_triangles(scene, usable, svo, layout);
    stats.voxelize_seconds = seconds_since(phase);
    stats.triangle_voxel_pairs = voxelized.keys.size();

    phase = Clock::now();
    tbb::parallel_sort(voxelized.keys.begin(), voxelized.keys.end());
    stats.sort_seconds = seconds_since(phase);

    phase = Clock::now();
    Leaves leaves = dedupe_into_leaves(voxelized.keys, voxelized.triangle_normals, layout);
    stats.leaves_seconds = seconds_since(phase);

    phase = Clock::now();
    build_hierarchy(std::move(leaves), svo);
    stats.hierarchy_seconds = seconds_since(phase);
  }

  stats.total_seconds = seconds_since(start);
  stats.nodes = svo.nodes.size();
  stats.leaves = svo.level_begin[svo.depth + 1] - svo.level_begin[svo.depth];
  stats.bytes_per_node = svo.nodes.empty() ? 0 : double(sizeof(formats::SvoNode) * svo.nodes.size()) / double(svo.nodes.size());
  stats.total_bytes = sizeof(formats::SvoNode) * svo.nodes.size() + sizeof(uint32_t) * svo.level_begin.size();
  if (statistics) *statistics = stats;
  return svo;
}

}  // namespace exitance
