// Voxelization into the sparse voxel octree: the leaf set against brute force, the octree's
// links and order, two-sided normals, depth and scale extremes. Cases named SvoBuildStress.* are
// registered with the `stress` label, the rest with `unit`.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "exitance/bake/voxelize/svo_build.h"
#include "exitance/formats/svo_file.h"
#include "morton_code.h"
#include "triangle_box_overlap.h"
#include "triangle_voxel_overlap.h"

namespace exitance {
namespace {

using Cell = std::tuple<uint32_t, uint32_t, uint32_t>;

void add_triangle(Scene& scene, Vec3 a, Vec3 b, Vec3 c) {
  for (Vec3 p : {a, b, c}) scene.positions.push_back(p);
  const Vec3 n = normalize(cross(b - a, c - a));
  for (int i = 0; i < 3; ++i) scene.normals.push_back(n), scene.uv0.push_back({}), scene.lightmap_uv.push_back({});
  scene.triangle_material.push_back(0);
  scene.triangle_instance.push_back(0);
}

// An axis-aligned rectangle: `axis` is its normal axis, at coordinate `at`; [lo, hi] on the other
// two axes (axis+1)%3 and (axis+2)%3. `facing` +1/-1 picks the winding, i.e. which way it faces.
struct AxisQuad {
  int axis;
  double at;
  double lo[2], hi[2];
  int facing;
};

Vec3 point(int axis, double at, double p, double q) {
  Vec3 v;
  v[axis] = float(at), v[(axis + 1) % 3] = float(p), v[(axis + 2) % 3] = float(q);
  return v;
}

void add_quad(Scene& scene, const AxisQuad& quad) {
  const Vec3 a = point(quad.axis, quad.at, quad.lo[0], quad.lo[1]), b = point(quad.axis, quad.at, quad.hi[0], quad.lo[1]),
             c = point(quad.axis, quad.at, quad.hi[0], quad.hi[1]), d = point(quad.axis, quad.at, quad.lo[0], quad.hi[1]);
  // (p, q) counter-clockwise faces +axis.
  if (quad.facing > 0) {
    add_triangle(scene, a, b, c), add_triangle(scene, a, c, d);
  } else {
    add_triangle(scene, a, c, b), add_triangle(scene, a, d, c);
  }
}

Scene scene_of(const std::vector<AxisQuad>& quads) {
  Scene scene;
  scene.materials.push_back(Material{});
  for (const AxisQuad& quad : quads) add_quad(scene, quad);
  return scene;
}

// The six faces of a box, outward-facing.
std::vector<AxisQuad> box_faces(Vec3 lo, Vec3 hi) {
  std::vector<AxisQuad> faces;
  for (int axis = 0; axis < 3; ++axis) {
    const int p = (axis + 1) % 3, q = (axis + 2) % 3;
    faces.push_back({axis, lo[axis], {lo[p], lo[q]}, {hi[p], hi[q]}, -1});
    faces.push_back({axis, hi[axis], {lo[p], lo[q]}, {hi[p], hi[q]}, +1});
  }
  return faces;
}

// Brute force, independent of the voxelizer: a closed leaf box and an axis-aligned rectangle
// overlap exactly when their intervals overlap on all three axes. Every coordinate of the
// rectangle must be clear of leaf faces (checked), so rounding cannot decide a case either way.
std::set<Cell> brute_force_leaves(const formats::SparseVoxelOctree& svo, const std::vector<AxisQuad>& quads) {
  const double leaf = double(svo.size) / double(svo.resolution());
  auto grid = [&](int axis, double x) { return (x - double(svo.origin[size_t(axis)])) / leaf; };
  auto assert_off_grid = [](double g) {
    const double distance = std::fabs(g - std::round(g));
    EXPECT_GT(distance, 1e-3) << "test geometry lies on a leaf face (grid coordinate " << g << ")";
  };
  std::set<Cell> cells;
  for (const AxisQuad& quad : quads) {
    double lo[3], hi[3];
    lo[quad.axis] = hi[quad.axis] = grid(quad.axis, quad.at);
    for (int i = 0; i < 2; ++i) {
      const int a = (quad.axis + 1 + i) % 3;
      lo[a] = grid(a, quad.lo[i]), hi[a] = grid(a, quad.hi[i]);
    }
    for (int a = 0; a < 3; ++a) assert_off_grid(lo[a]), assert_off_grid(hi[a]);
    const uint32_t n = svo.resolution();
    for (uint32_t x = 0; x < n; ++x)
      for (uint32_t y = 0; y < n; ++y)
        for (uint32_t z = 0; z < n; ++z) {
          const double c[3] = {double(x), double(y), double(z)};
          bool overlap = true;
          for (int a = 0; a < 3; ++a) overlap = overlap && c[a] <= hi[a] && lo[a] <= c[a] + 1;
          if (overlap) cells.insert({x, y, z});
        }
  }
  return cells;
}

// Integer cell of every node at its own level, top-down through the child masks.
std::vector<Cell> node_cells(const formats::SparseVoxelOctree& svo) {
  std::vector<Cell> cells(svo.nodes.size(), {0, 0, 0});
  for (size_t i = 0; i < svo.nodes.size(); ++i) {
    uint32_t child = svo.nodes[i].first_child;
    const auto [x, y, z] = cells[i];
    for (uint32_t octant = 0; octant < 8; ++octant)
      if (svo.nodes[i].child_mask & (1u << octant))
        cells[child++] = {2 * x + (octant & 1u), 2 * y + ((octant >> 1) & 1u), 2 * z + ((octant >> 2) & 1u)};
  }
  return cells;
}

std::set<Cell> leaf_cells(const formats::SparseVoxelOctree& svo) {
  const std::vector<Cell> cells = node_cells(svo);
  return {cells.begin() + svo.level_begin[svo.depth], cells.begin() + svo.level_begin[svo.depth + 1]};
}

std::array<float, 3> leaf_centre(const formats::SparseVoxelOctree& svo, const Cell& cell) {
  const float leaf = svo.voxel_size(svo.depth);
  return {svo.origin[0] + (float(std::get<0>(cell)) + 0.5f) * leaf, svo.origin[1] + (float(std::get<1>(cell)) + 0.5f) * leaf,
          svo.origin[2] + (float(std::get<2>(cell)) + 0.5f) * leaf};
}

// Links, order and flags of a well-formed octree, and every leaf reachable at its centre.
void expect_well_formed(const formats::SparseVoxelOctree& svo) {
  EXPECT_NO_THROW(formats::validate_octree(svo, "built octree"));  // svo.bin's own structure check
  ASSERT_EQ(svo.level_begin.size(), svo.depth + 2);
  ASSERT_FALSE(svo.nodes.empty());
  EXPECT_EQ(svo.level_begin[0], 0u);
  EXPECT_EQ(svo.level_begin[1], 1u);  // one root
  EXPECT_EQ(svo.level_begin[svo.depth + 1], svo.nodes.size());
  EXPECT_EQ(svo.nodes[0].parent, formats::kSvoNoParent);
  const std::vector<Cell> cells = node_cells(svo);
  uint32_t expected_first_child = 1;  // breadth-first: children of consecutive nodes are consecutive
  for (uint32_t level = 0; level <= svo.depth; ++level) {
    ASSERT_LE(svo.level_begin[level], svo.level_begin[level + 1]);
    EXPECT_LT(svo.level_begin[level], svo.level_begin[level + 1]) << "empty level " << level;
    uint64_t previous_code = 0;
    for (uint32_t i = svo.level_begin[level]; i < svo.level_begin[level + 1]; ++i) {
      const formats::SvoNode& node = svo.nodes[i];
      ASSERT_EQ(node.level, level);
      const auto [x, y, z] = cells[i];
      const uint64_t code = morton::encode(x, y, z);
      if (i > svo.level_begin[level]) {
        EXPECT_LT(previous_code, code) << "level " << level << " not in Morton order";
      }
      previous_code = code;
      const std::array<float, 3> n = formats::decode_octahedral_normal(node.normal_oct);
      EXPECT_NEAR(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1.0f, 1e-3f);
      for (int side = 0; side < 2; ++side)
        for (float e : formats::svo_node_exitance(svo, i, side)) EXPECT_EQ(e, 0.0f);
      EXPECT_EQ(node.flags & ~uint16_t(formats::kSvoLeaf), 0) << "no Lit/Filled flags before lighting";
      if (level == svo.depth) {
        EXPECT_EQ(node.flags, formats::kSvoLeaf);
        EXPECT_EQ(node.child_mask, 0);
        EXPECT_EQ(formats::svo_find_node(svo, leaf_centre(svo, cells[i]), svo.depth), i);
        continue;
      }
      EXPECT_EQ(node.flags & formats::kSvoLeaf, 0);
      ASSERT_NE(node.child_mask, 0) << "internal node without children";
      EXPECT_EQ(node.first_child, expected_first_child);
      const uint32_t children = uint32_t(std::popcount(uint32_t(node.child_mask)));
      expected_first_child += children;
      ASSERT_GE(node.first_child, svo.level_begin[level + 1]);
      ASSERT_LE(node.first_child + children, svo.level_begin[level + 2]);
      for (uint32_t c = 0; c < children; ++c) EXPECT_EQ(svo.nodes[node.first_child + c].parent, i);
    }
  }
  EXPECT_EQ(expected_first_child, svo.nodes.size());
}

// Random points on every triangle must land in a leaf (conservative voxelization).
void expect_surface_covered(const formats::SparseVoxelOctree& svo, const Scene& scene, int points_per_triangle) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0, 1);
  for (size_t t = 0; t < scene.triangle_count(); ++t)
    for (int i = 0; i < points_per_triangle; ++i) {
      float a = u(rng), b = u(rng);
      if (a + b > 1) a = 1 - a, b = 1 - b;
      const Vec3* v = &scene.positions[t * 3];
      const Vec3 p = v[0] + (v[1] - v[0]) * a + (v[2] - v[0]) * b;
      const uint32_t node = formats::svo_find_node(svo, {p.x, p.y, p.z}, svo.depth);
      ASSERT_NE(node, formats::kSvoNoParent);
      EXPECT_EQ(svo.nodes[node].level, svo.depth) << "triangle " << t << " point not in a leaf";
    }
}

TEST(SvoBuild, MortonTripletsAreOctantsFromTheTop) {
  const uint32_t depth = 5;
  const uint64_t code = morton::encode(0b10110, 0b01100, 0b11001);
  const uint32_t expected[5] = {0b101, 0b110, 0b011, 0b001, 0b100};  // per level: z y x bits of that level
  for (uint32_t level = 1; level <= depth; ++level) EXPECT_EQ(morton::octant_at_level(code, level, depth), expected[level - 1]);
  const morton::Cell cell = morton::decode(morton::encode(2097151, 12345, 1));
  EXPECT_EQ(cell.x, 2097151u);
  EXPECT_EQ(cell.y, 12345u);
  EXPECT_EQ(cell.z, 1u);
}

// The voxelizer's hoisted form of the separating axis test agrees with the reference form.
TEST(SvoBuild, FastOverlapMatchesReferenceSeparatingAxisTest) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coordinate(-1.0, 5.0);
  int overlaps = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const Double3 a{coordinate(rng), coordinate(rng), coordinate(rng)}, b{coordinate(rng), coordinate(rng), coordinate(rng)},
                  c{coordinate(rng), coordinate(rng), coordinate(rng)};
    const TriangleVoxelOverlap fast(a, b, c);
    for (int x = 0; x < 4; ++x)
      for (int y = 0; y < 4; ++y)
        for (int z = 0; z < 4; ++z) {
          const bool reference = triangle_overlaps_box({x + 0.5, y + 0.5, z + 0.5}, {0.5, 0.5, 0.5}, a, b, c);
          // The fast test leaves the cell's own three axes to the caller's bounding-box loop.
          bool in_box = true;
          for (int k = 0; k < 3; ++k) {
            const double cell = k == 0 ? x : (k == 1 ? y : z);
            in_box = in_box && std::min({a[k], b[k], c[k]}) <= cell + 1 && std::max({a[k], b[k], c[k]}) >= cell;
          }
          ASSERT_EQ(reference, in_box && fast.overlaps({double(x), double(y), double(z)}))
              << "trial " << trial << " cell " << x << "," << y << "," << z;
          overlaps += reference;
        }
  }
  EXPECT_GT(overlaps, 10000);  // the comparison saw both outcomes often
}

TEST(SvoBuild, SingleQuadGivesExactlyTheBruteForceLeaves) {
  // 2.9 × 1.13 in the plane z = 5.3: the extent 2.9 spans 29 leaves of 0.1 at depth 5.
  const std::vector<AxisQuad> quads = {{2, 5.3, {3.7, -2.1}, {6.6, -0.97}, +1}};
  const Scene scene = scene_of(quads);
  SvoBuildStatistics stats;
  const formats::SparseVoxelOctree svo = build_sparse_voxel_octree(scene, {5}, &stats);
  EXPECT_NEAR(svo.voxel_size(5), 0.1f, 1e-5f);
  const std::set<Cell> expected = brute_force_leaves(svo, quads);
  EXPECT_EQ(expected.size(), 30u * 12u);  // x: 1.75 .. 30.75 → 30 leaves; y: 11.3 leaves off-grid → 12
  EXPECT_EQ(leaf_cells(svo), expected);
  EXPECT_EQ(stats.leaves, expected.size());
  EXPECT_EQ(stats.nodes, svo.nodes.size());
  EXPECT_EQ(stats.bytes_per_node, 28.0);
  EXPECT_EQ(stats.total_bytes, 28 * svo.nodes.size() + 4 * svo.level_begin.size());
  EXPECT_EQ(stats.triangles_voxelized, 2u);
  expect_well_formed(svo);
  for (uint32_t i = 0; i < svo.nodes.size(); ++i)  // every node faces +z
    EXPECT_GT(formats::decode_octahedral_normal(svo.nodes[i].normal_oct)[2], 0.999f);
}

TEST(SvoBuild, BoxLeavesMatchBruteForce) {
  const std::vector<AxisQuad> quads = box_faces({0.31f, -1.2f, 2.05f}, {3.21f, -0.07f, 2.82f});
  const Scene scene = scene_of(quads);
  const formats::SparseVoxelOctree svo = build_sparse_voxel_octree(scene, {6});
  const std::set<Cell> expected = brute_force_leaves(svo, quads);
  EXPECT_EQ(leaf_cells(svo), expected);
  expect_well_formed(svo);
  expect_surface_covered(svo, scene, 200);
}

// Tilted triangles of all sizes against the reference separating axis test on every leaf: catches
// cells the voxelizer's column walk might skip.
TEST(SvoBuild, TiltedTrianglesMatchReferenceOnEveryLeaf) {
  Scene scene;
  scene.materials.push_back(Material{});
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> coordinate(-3, 4), offset(-0.6f, 0.6f);
  for (int t = 0; t < 24; ++t) {
    const Vec3 a{coordinate(rng), coordinate(rng), coordinate(rng)};
    const float scale = t < 8 ? 5.0f : (t < 16 ? 1.0f : 0.1f);  // large, medium, small
    add_triangle(scene, a, a + Vec3{offset(rng), offset(rng), offset(rng)} * scale,
                 a + Vec3{offset(rng), offset(rng), offset(rng)} * scale);
  }
  const formats::SparseVoxelOctree svo = build_sparse_voxel_octree(scene, {5});
  const double leaf = double(svo.size) / 32.0;
  std::set<Cell> expected;
  for (size_t t = 0; t < scene.triangle_count(); ++t) {
    Double3 v[3];
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) v[i][size_t(k)] = (double(scene.positions[t * 3 + size_t(i)][k]) - svo.origin[size_t(k)]) / leaf;
    for (uint32_t x = 0; x < 32; ++x)
      for (uint32_t y = 0; y < 32; ++y)
        for (uint32_t z = 0; z < 32; ++z)
          if (triangle_overlaps_box({x + 0.5, y + 0.5, z + 0.5}, {0.5, 0.5, 0.5}, v[0], v[1], v[2])) expected.insert({x, y, z});
  }
  EXPECT_EQ(leaf_cells(svo), expected);
  expect_well_formed(svo);
}

// Two opposite-facing walls 0.1 leaf apart share one layer of leaves: a plain average would cancel.
TEST(SvoBuild, ThinDoubleWallKeepsNormalAlongTheWall) {
  for (double back_height : {2.0, 1.7}) {  // equal areas (the mean cancels exactly) and unequal
    const double gap = 0.01;                // the walls span 2.0, 0.1 at depth 5 → a leaf of ≈0.069
    const Scene scene = scene_of({{0, 1.0, {0, 0}, {2.0, 2.0}, +1}, {0, 1.0 + gap, {0, 0}, {back_height, 2.0}, -1}});
    const formats::SparseVoxelOctree svo = build_sparse_voxel_octree(scene, {5});
    ASSERT_LT(gap, 0.2 * svo.voxel_size(5));
    expect_well_formed(svo);
    const std::vector<Cell> cells = node_cells(svo);
    std::set<uint32_t> layers;
    for (uint32_t i = 0; i < svo.nodes.size(); ++i) {
      const std::array<float, 3> n = formats::decode_octahedral_normal(svo.nodes[i].normal_oct);
      EXPECT_GT(std::fabs(n[0]), 0.999f) << "node " << i << " level " << int(svo.nodes[i].level);
      if (svo.nodes[i].level == svo.depth) layers.insert(std::get<0>(cells[i]));
    }
    EXPECT_EQ(layers.size(), 1u) << "both walls in one layer of leaves";
  }
}

// A wall two leaves thick: its faces land in leaves on either side of the cube's middle, with
// opposite normals of equal weight, and meet in the root together with a small floor patch. A
// plain average would cancel the walls and leave the floor's +y; aligned, the root stays along x.
TEST(SvoBuild, OpposedChildrenDoNotCancelInParents) {
  const std::vector<AxisQuad> quads = {{0, 1.0, {0, 0}, {2.0, 2.0}, +1},
                                       {0, 1.15, {0, 0}, {2.0, 2.0}, -1},
                                       {1, 1.03, {0.53, 1.02}, {0.71, 1.12}, +1}};
  const formats::SparseVoxelOctree svo = build_sparse_voxel_octree(scene_of(quads), {5});
  EXPECT_EQ(leaf_cells(svo), brute_force_leaves(svo, quads));
  expect_well_formed(svo);
  int negative = 0, positive = 0;
  for (uint32_t i = svo.level_begin[svo.depth]; i < svo.nodes.size(); ++i) {
    const std::array<float, 3> n = formats::decode_octahedral_normal(svo.nodes[i].normal_oct);
    if (n[0] > 0.999f) ++positive;
    if (n[0] < -0.999f) ++negative;
  }
  EXPECT_GT(positive, 800);
  EXPECT_GT(negative, 800);
  for (uint32_t i = 0; i < svo.level_begin[2]; ++i)  // the root and its children
    EXPECT_GT(std::fabs(formats::decode_octahedral_normal(svo.nodes[i].normal_oct)[0]), 0.99f) << "node " << i;
}

TEST(SvoBuild, DepthOneAndDepthTwelve) {
  const Scene box = scene_of(box_faces({0, 0, 0}, {1.0f, 0.6f, 0.3f}));
  const formats::SparseVoxelOctree coarse = build_sparse_voxel_octree(box, {1});
  expect_well_formed(coarse);
  expect_surface_covered(coarse, box, 50);
  // Depth 12 over a long, sparse scene (two small squares 100 apart), so 4096³ stays cheap.
  const Scene sparse = scene_of({{2, 0.01, {0.003, 0.004}, {0.2, 0.25}, +1}, {1, 0.02, {0.01, 99.9}, {0.17, 100.0}, -1}});
  SvoBuildStatistics stats;
  const formats::SparseVoxelOctree fine = build_sparse_voxel_octree(sparse, {12}, &stats);
  EXPECT_EQ(fine.resolution(), 4096u);
  expect_well_formed(fine);
  expect_surface_covered(fine, sparse, 200);
  EXPECT_GT(stats.leaves, 50u);
}

TEST(SvoBuild, EmptyAndDegenerateScenes) {
  Scene empty;
  const formats::SparseVoxelOctree none = build_sparse_voxel_octree(empty, {8});
  EXPECT_TRUE(none.nodes.empty());
  EXPECT_EQ(none.level_begin, std::vector<uint32_t>(10, 0u));
  EXPECT_EQ(formats::svo_find_node(none, {0, 0, 0}, 8), formats::kSvoNoParent);
  EXPECT_NO_THROW(formats::validate_octree(none, "empty octree"));

  Scene bad;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  add_triangle(bad, {0, 0, 0}, {1, 1, 1}, {2, 2, 2});  // collinear: zero area
  add_triangle(bad, {0, 0, 0}, {nan, 0, 0}, {0, 1, 0});
  add_triangle(bad, {1, 1, 1}, {1, 1, 1}, {1, 1, 1});
  SvoBuildStatistics stats;
  EXPECT_TRUE(build_sparse_voxel_octree(bad, {6}, &stats).nodes.empty());
  EXPECT_EQ(stats.triangles_skipped, 3u);

  add_triangle(bad, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  const formats::SparseVoxelOctree one = build_sparse_voxel_octree(bad, {6}, &stats);
  EXPECT_EQ(stats.triangles_skipped, 3u);
  EXPECT_EQ(stats.triangles_voxelized, 1u);
  expect_well_formed(one);

  // A triangle far below a leaf (its area vanishes in grid units) keeps its own normal, +x here.
  Scene tiny;
  add_triangle(tiny, {0, 0, 0}, {0, 1e-20f, 0}, {0, 0, 1e-20f});
  add_triangle(tiny, {5, 5, 5}, {6, 5, 5}, {5, 6, 5});
  const formats::SparseVoxelOctree with_tiny = build_sparse_voxel_octree(tiny, {6}, &stats);
  EXPECT_EQ(stats.triangles_voxelized, 2u);
  expect_well_formed(with_tiny);
  const uint32_t tiny_leaf = formats::svo_find_node(with_tiny, {0, 0, 0}, 6);
  ASSERT_NE(tiny_leaf, formats::kSvoNoParent);
  EXPECT_EQ(with_tiny.nodes[tiny_leaf].level, 6);
  EXPECT_GT(formats::decode_octahedral_normal(with_tiny.nodes[tiny_leaf].normal_oct)[0], 0.999f);

  EXPECT_THROW(build_sparse_voxel_octree(bad, {0}), std::invalid_argument);
  EXPECT_THROW(build_sparse_voxel_octree(bad, {13}), std::invalid_argument);
}

TEST(SvoBuild, DepthFromResolutionAndTexelDensity) {
  EXPECT_EQ(svo_depth_from_resolution(2), 1u);
  EXPECT_EQ(svo_depth_from_resolution(256), 8u);
  EXPECT_EQ(svo_depth_from_resolution(4096), 12u);
  for (uint32_t bad : {0u, 1u, 3u, 100u, 8192u}) EXPECT_THROW(svo_depth_from_resolution(bad), std::invalid_argument);

  const Scene room = scene_of(box_faces({0, 0, 0}, {10, 3, 8}));
  EXPECT_EQ(default_svo_depth(room, 64), 8u);  // leaf 4/64 = 1/16: 10 / (1/16) = 160 → 2^8
  EXPECT_EQ(default_svo_depth(room, 4), 4u);   // leaf 1: 10 → 2^4
  EXPECT_EQ(default_svo_depth(room, 1e6f), 12u);
  EXPECT_EQ(default_svo_depth(room, 1e-3f), 1u);
  EXPECT_EQ(default_svo_depth(Scene{}, 64), 1u);
  EXPECT_THROW(default_svo_depth(room, 0), std::invalid_argument);
  EXPECT_THROW(default_svo_depth(room, std::numeric_limits<float>::quiet_NaN()), std::invalid_argument);
}

// Geometry 1e5 units from the origin: float positions there are quantized to ~0.008, so compare
// with brute force on the stored (already rounded) vertices and check coverage and finiteness.
TEST(SvoBuildStress, FarFromTheOrigin) {
  const Vec3 offset{1e5f, -1e5f, 1e5f};
  const Vec3 lo = offset + Vec3{0.31f, -1.2f, 2.05f}, hi = offset + Vec3{3.21f, -0.07f, 2.82f};
  const Scene scene = scene_of(box_faces(lo, hi));
  SvoBuildStatistics stats;
  const formats::SparseVoxelOctree svo = build_sparse_voxel_octree(scene, {7}, &stats);
  expect_well_formed(svo);
  const std::set<Cell> expected = brute_force_leaves(svo, box_faces(lo, hi));
  EXPECT_EQ(leaf_cells(svo), expected);
  const Scene near_origin = scene_of(box_faces(lo - offset, hi - offset));
  const SvoBuildStatistics at_origin = [&] {
    SvoBuildStatistics s;
    build_sparse_voxel_octree(near_origin, {7}, &s);
    return s;
  }();
  EXPECT_NEAR(double(stats.leaves), double(at_origin.leaves), 0.05 * double(at_origin.leaves));
}

TEST(SvoBuildStress, TinyScale) {
  const std::vector<AxisQuad> unit = box_faces({0.31f, -1.2f, 2.05f}, {3.21f, -0.07f, 2.82f});
  std::vector<AxisQuad> tiny = unit;
  for (AxisQuad& q : tiny) {
    q.at *= 1e-3;
    for (int i = 0; i < 2; ++i) q.lo[i] *= 1e-3, q.hi[i] *= 1e-3;
  }
  const Scene scene = scene_of(tiny);
  const formats::SparseVoxelOctree svo = build_sparse_voxel_octree(scene, {6});
  expect_well_formed(svo);
  EXPECT_EQ(leaf_cells(svo), brute_force_leaves(svo, tiny));
  EXPECT_EQ(leaf_cells(svo), leaf_cells(build_sparse_voxel_octree(scene_of(unit), {6})));
}

TEST(SvoBuildStress, EveryDepthIsWellFormed) {
  const Scene box = scene_of(box_faces({-0.4f, 0.1f, 0.2f}, {0.5f, 0.45f, 0.6f}));
  for (uint32_t depth = 1; depth <= 9; ++depth) {
    SCOPED_TRACE(depth);
    const formats::SparseVoxelOctree svo = build_sparse_voxel_octree(box, {depth});
    expect_well_formed(svo);
    expect_surface_covered(svo, box, 20);
  }
}

}  // namespace
}  // namespace exitance
