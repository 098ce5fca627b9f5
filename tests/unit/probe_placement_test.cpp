// Probe placement: grid layout, probes inside solid geometry moved out or marked invalid, probes
// far from all geometry skipped, and the spacing limit.
#include <gtest/gtest.h>

#include <cmath>

#include "exitance/bake/probes/probe_placement.h"
#include "support/test_scenes.h"

namespace exitance {
namespace {

using formats::ProbeState;
using testing::add_material;
using testing::add_quad;

// Axis-aligned box [lo, hi] with every face pointing outward (a solid pillar).
void add_outward_box(Scene& scene, Vec3 lo, Vec3 hi, uint32_t material) {
  const Vec3 d = hi - lo;
  const Vec3 ex{d.x, 0, 0}, ey{0, d.y, 0}, ez{0, 0, d.z};
  add_quad(scene, lo, ex, ez, material);       // floor face, normal -y
  add_quad(scene, lo + ey, ez, ex, material);  // top, normal +y
  add_quad(scene, lo, ey, ex, material);       // z = lo, normal -z
  add_quad(scene, lo + ez, ex, ey, material);  // z = hi, normal +z
  add_quad(scene, lo, ez, ey, material);       // x = lo, normal -x
  add_quad(scene, lo + ex, ey, ez, material);  // x = hi, normal +x
}

bool inside_box(const std::array<float, 3>& p, Vec3 lo, Vec3 hi) {
  return p[0] > lo.x && p[0] < hi.x && p[1] > lo.y && p[1] < hi.y && p[2] > lo.z && p[2] < hi.z;
}

const formats::ProbeRecord& probe_nearest(const formats::ProbeGrid& grid, Vec3 p) {
  size_t best = 0;
  float best_d = 1e30f;
  for (uint32_t z = 0; z < grid.counts[2]; ++z)
    for (uint32_t y = 0; y < grid.counts[1]; ++y)
      for (uint32_t x = 0; x < grid.counts[0]; ++x) {
        const Vec3 g{grid.origin[0] + x * grid.spacing[0], grid.origin[1] + y * grid.spacing[1],
                     grid.origin[2] + z * grid.spacing[2]};
        if (length(g - p) < best_d) best_d = length(g - p), best = grid.index(x, y, z);
      }
  return grid.probes[best];
}

// A closed 8 x 4 x 8 room with a thick pillar (2.2 x 4 x 2.2) and a thin one (0.4 x 4 x 0.4).
Scene room_with_pillars(Vec3& thick_lo, Vec3& thick_hi, Vec3& thin_lo, Vec3& thin_hi) {
  Scene scene;
  const uint32_t grey = add_material(scene, {0.5f, 0.5f, 0.5f});
  testing::add_inward_box(scene, {0, 0, 0}, {8, 4, 8}, grey);
  thick_lo = {0.9f, 0, 0.9f}, thick_hi = {3.1f, 4, 3.1f};
  thin_lo = {6.3f, 0, 6.3f}, thin_hi = {6.7f, 4, 6.7f};
  add_outward_box(scene, thick_lo, thick_hi, grey);
  add_outward_box(scene, thin_lo, thin_hi, grey);
  return scene;
}

TEST(ProbePlacement, GridCoversBoundsAndSolidGeometryIsHandled) {
  Vec3 thick_lo, thick_hi, thin_lo, thin_hi;
  const Scene scene = room_with_pillars(thick_lo, thick_hi, thin_lo, thin_hi);
  const EmbreeScene embree(scene);
  ProbePlacementSettings settings;
  settings.spacing = 1.0f;
  const ProbePlacement placement = place_probes(scene, embree, nullptr, settings);
  const formats::ProbeGrid& grid = placement.grid;
  EXPECT_EQ(grid.counts[0], 8u);
  EXPECT_EQ(grid.counts[1], 4u);
  EXPECT_EQ(grid.counts[2], 8u);
  EXPECT_FLOAT_EQ(grid.origin[0], 0.5f);  // cell centres: no probe on the room's walls
  EXPECT_EQ(placement.valid + placement.moved + placement.invalid + placement.skipped, grid.probes.size());
  EXPECT_EQ(placement.skipped, 0u);
  // Probes (1.5 | 2.5, y, 1.5 | 2.5) are 0.6 or more inside the thick pillar: half a spacing
  // cannot get them out.
  EXPECT_EQ(probe_nearest(grid, {1.5f, 2.5f, 1.5f}).state, ProbeState::Invalid);
  EXPECT_EQ(probe_nearest(grid, {2.5f, 0.5f, 2.5f}).state, ProbeState::Invalid);
  EXPECT_EQ(placement.invalid, 4u * 4u);
  // Probe (6.5, y, 6.5) sits in the thin pillar: it moves out, and ends outside the pillar.
  const formats::ProbeRecord& thin = probe_nearest(grid, {6.5f, 2.5f, 6.5f});
  EXPECT_EQ(thin.state, ProbeState::Moved);
  EXPECT_FALSE(inside_box(thin.position, thin_lo, thin_hi));
  // A probe in open air is valid and unmoved.
  const formats::ProbeRecord& open = probe_nearest(grid, {5.5f, 1.5f, 1.5f});
  EXPECT_EQ(open.state, ProbeState::Valid);
  EXPECT_FLOAT_EQ(open.position[0], 5.5f);
  // No usable probe lies inside a pillar.
  for (const formats::ProbeRecord& r : grid.probes)
    if (formats::probe_is_usable(r)) {
      EXPECT_FALSE(inside_box(r.position, thick_lo, thick_hi));
      EXPECT_FALSE(inside_box(r.position, thin_lo, thin_hi));
    }
}

TEST(ProbePlacement, ProbesFarFromGeometryAreSkipped) {
  Scene scene;
  const uint32_t grey = add_material(scene, {0.5f, 0.5f, 0.5f});
  add_quad(scene, {0, 0, 1}, {1, 0, 0}, {0, 0, -1}, grey);       // 1 x 1 floor at the origin
  add_quad(scene, {99, 0, 1}, {1, 0, 0}, {0, 0, -1}, grey);      // and one 99 units away
  const EmbreeScene embree(scene);
  ProbePlacementSettings settings;
  settings.spacing = 10.0f;
  const ProbePlacement placement = place_probes(scene, embree, nullptr, settings);
  EXPECT_EQ(placement.grid.counts[0], 10u);
  EXPECT_EQ(placement.grid.counts[1], 2u);  // a flat scene: one layer above, one below
  EXPECT_FLOAT_EQ(placement.grid.origin[1], -5.0f);
  // Probes within 3 spacings of either quad are kept; those in the 40-unit gap are skipped.
  EXPECT_GT(placement.skipped, 0u);
  EXPECT_GT(placement.valid, 0u);
  EXPECT_EQ(probe_nearest(placement.grid, {45, 5, 0}).state, ProbeState::Skipped);
  EXPECT_EQ(probe_nearest(placement.grid, {5, 5, 0}).state, ProbeState::Valid);
}

// The middle of a closed room far more than 3 spacings from every wall keeps its probes: they are
// far from geometry but not in the open (no test ray escapes), and objects moving there need them.
TEST(ProbePlacement, MiddleOfAClosedRoomIsNotSkipped) {
  Scene scene;
  const uint32_t grey = add_material(scene, {0.5f, 0.5f, 0.5f});
  testing::add_inward_box(scene, {0, 0, 0}, {12, 12, 12}, grey);
  const EmbreeScene embree(scene);
  ProbePlacementSettings settings;
  settings.spacing = 1.0f;
  const ProbePlacement placement = place_probes(scene, embree, nullptr, settings);
  EXPECT_EQ(placement.skipped, 0u);
  EXPECT_EQ(probe_nearest(placement.grid, {6, 6, 6}).state, ProbeState::Valid);
  // The same distance from a lone floor in the open is skipped.
  Scene open;
  const uint32_t floor_grey = add_material(open, {0.5f, 0.5f, 0.5f});
  add_quad(open, {0, 0, 12}, {12, 0, 0}, {0, 0, -12}, floor_grey);
  add_quad(open, {0, 12, 0}, {12, 0, 0}, {0, 0, 12}, floor_grey);  // a ceiling 12 above: the room's bounds, open sides
  const EmbreeScene open_embree(open);
  const ProbePlacement open_placement = place_probes(open, open_embree, nullptr, settings);
  EXPECT_EQ(probe_nearest(open_placement.grid, {6, 6, 6}).state, ProbeState::Skipped);
}

// The point query measures the distance to the triangle itself, not to its bounding box: a long
// diagonal triangle's box corner is far from it.
TEST(ProbePlacement, DistanceQueryIsToTheTriangle) {
  Scene scene;
  const uint32_t grey = add_material(scene, {0.5f, 0.5f, 0.5f});
  add_quad(scene, {0, 0, 0}, {10, 10, 0}, {0, 0, 1}, grey);  // a strip along the diagonal y = x
  const EmbreeScene embree(scene);
  EXPECT_NEAR(embree.distance_to_nearest_triangle({5, 5, 0.5f}, 100), 0.0f, 1e-5f);
  EXPECT_NEAR(embree.distance_to_nearest_triangle({10, 0, 0.5f}, 100), std::sqrt(50.0f), 1e-4f);  // box corner
  EXPECT_NEAR(embree.distance_to_nearest_triangle({-3, -4, 0.5f}, 100), 5.0f, 1e-4f);            // a vertex
  EXPECT_EQ(embree.distance_to_nearest_triangle({10, 0, 0.5f}, 7.0f), INFINITY);                  // beyond the radius
}

TEST(ProbePlacement, OccupiedVoxelMovesAProbeOffASurface) {
  Scene scene;
  const uint32_t grey = add_material(scene, {0.5f, 0.5f, 0.5f});
  testing::add_inward_box(scene, {0, 0, 0}, {4, 4, 4}, grey);
  add_quad(scene, {1, 1.5f, 3}, {2, 0, 0}, {0, 0, -2}, grey);  // a shelf at y = 1.5 through grid points
  const EmbreeScene embree(scene);
  // An octree by hand whose only leaf, [1.5, 2]^3, holds grid point (1.5, 1.5, 1.5) on the shelf.
  formats::SparseVoxelOctree svo;
  svo.origin = {1.0f, 1.0f, 1.0f};
  svo.size = 1.0f;
  svo.depth = 1;
  svo.nodes.resize(2);
  svo.nodes[0].first_child = 1;
  svo.nodes[0].child_mask = 1u << 7;  // octant (+x, +y, +z) of [1, 2]^3
  svo.nodes[1].parent = 0;
  svo.nodes[1].level = 1;
  svo.nodes[1].flags = formats::kSvoLeaf;
  svo.level_begin = {0, 1, 2};
  ProbePlacementSettings settings;
  settings.spacing = 1.0f;
  const ProbePlacement with_svo = place_probes(scene, embree, &svo, settings);
  const formats::ProbeRecord& p = probe_nearest(with_svo.grid, {1.5f, 1.5f, 1.5f});
  EXPECT_EQ(p.state, ProbeState::Moved);
  EXPECT_EQ(formats::svo_find_node(svo, p.position, 1) == 1u, false);
}

TEST(ProbePlacement, TooFineASpacingIsRefused) {
  Scene scene;
  add_quad(scene, {0, 0, 1}, {1, 0, 0}, {0, 0, -1}, add_material(scene, {0.5f, 0.5f, 0.5f}));
  testing::add_inward_box(scene, {0, 0, 0}, {100, 100, 100}, 0);
  const EmbreeScene embree(scene);
  ProbePlacementSettings settings;
  settings.spacing = 0.01f;
  EXPECT_THROW(place_probes(scene, embree, nullptr, settings), std::invalid_argument);
  settings.spacing = -1.0f;
  EXPECT_THROW(place_probes(scene, embree, nullptr, settings), std::invalid_argument);
}

TEST(ProbePlacement, AutomaticSpacingIsATwelfthOfTheLargestExtent) {
  Scene scene;
  testing::add_inward_box(scene, {0, 0, 0}, {24, 6, 12}, add_material(scene, {0.5f, 0.5f, 0.5f}));
  EXPECT_FLOAT_EQ(automatic_probe_spacing(scene), 2.0f);
  EXPECT_FLOAT_EQ(automatic_probe_spacing(Scene{}), 1.0f);
}

}  // namespace
}  // namespace exitance
