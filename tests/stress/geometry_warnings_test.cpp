// Each kind of troubled geometry gets its own clear warning (stress suite), and the lighting
// stays finite on it.
#include <gtest/gtest.h>

#include <set>

#include "exitance/bake/raster/geometry_checks.h"
#include "support/test_scenes.h"

namespace exitance {
namespace {

using testing::add_inward_box;
using testing::add_material;
using testing::add_quad;
using testing::texel_at;

bool mentions(const std::vector<std::string>& lines, const std::string& text) {
  for (const auto& line : lines)
    if (line.find(text) != std::string::npos) return true;
  return false;
}

TEST(GeometryWarnings, CleanRoomHasNone) {
  Scene scene;
  add_inward_box(scene, {0, 0, 0}, {2, 2, 2}, add_material(scene, {0.5f, 0.5f, 0.5f}));
  PunctualLight light;
  light.position = {1, 1, 1};
  scene.lights.push_back(light);
  TexelGBuffer gbuffer;
  gbuffer.texels.push_back(texel_at({1, 0, 1}, {0, 1, 0}));
  EmbreeScene embree(scene);
  const GeometryCheckReport report = check_scene_geometry(scene, embree, gbuffer);
  EXPECT_TRUE(describe_geometry_problems(report, scene, "room.gltf").empty());
}

TEST(GeometryWarnings, EachProblemIsNamed) {
  Scene scene;
  const uint32_t grey = add_material(scene, {0.5f, 0.5f, 0.5f});
  add_inward_box(scene, {0, 0, 0}, {4, 4, 4}, grey);  // instance 0
  auto new_instance = [&] { scene.instances.back().name = "done"; };  // the next quad opens another
  // Closed outward boxes: one standing on the floor, one floating with a point light inside.
  auto add_outward_box = [&](Vec3 lo, Vec3 hi) {
    new_instance();
    const Vec3 d = hi - lo, ex{d.x, 0, 0}, ey{0, d.y, 0}, ez{0, 0, d.z};
    add_quad(scene, lo + ey, ez, ex, grey);
    add_quad(scene, lo, ex, ez, grey);
    add_quad(scene, lo, ey, ex, grey);
    add_quad(scene, lo + ez, ex, ey, grey);
    add_quad(scene, lo, ez, ey, grey);
    add_quad(scene, lo + ex, ey, ez, grey);
  };
  add_outward_box({1, 0, 1}, {2, 1, 2});
  add_outward_box({2.5f, 2, 0.5f}, {3.5f, 3, 1.5f});
  PunctualLight hidden;
  hidden.name = "InTheBox";
  hidden.position = {3, 2.5f, 1};
  scene.lights.push_back(hidden);
  // A second floor exactly on the first (coplanar overlap), and a zero-area emitter.
  new_instance();
  add_quad(scene, {0, 0, 4}, {4, 0, 0}, {0, 0, -4}, grey);
  add_quad(scene, {3, 3.5f, 3}, {0, 0, 0}, {0, 0, 0.5f}, add_material(scene, {0, 0, 0}, {1, 1, 1}));
  TexelGBuffer gbuffer;
  gbuffer.texels.push_back(texel_at({3, 0, 3}, {0, 1, 0}));        // on the doubled floor (instance 0)
  gbuffer.texels.push_back(texel_at({1.5f, 0, 1.5f}, {0, 1, 0}));  // floor under the standing box
  EmbreeScene embree(scene);
  const GeometryCheckReport report = check_scene_geometry(scene, embree, gbuffer);
  EXPECT_EQ(report.coplanar_texels, 2u);  // the doubled floor lies under both texels
  EXPECT_EQ(report.enclosed_texels, 1u);
  ASSERT_EQ(report.enclosed_lights.size(), 1u);
  EXPECT_EQ(report.unsampled_emitters, 2u);
  const auto lines = describe_geometry_problems(report, scene, "troubled.gltf");
  EXPECT_EQ(lines.size(), 4u);
  EXPECT_TRUE(mentions(lines, "'InTheBox' is enclosed"));
  EXPECT_TRUE(mentions(lines, "coplanar"));
  EXPECT_TRUE(mentions(lines, "back faces"));
  EXPECT_TRUE(mentions(lines, "zero area"));
  for (const auto& line : lines) EXPECT_EQ(line.find('\n'), std::string::npos);

  IntegratorSettings settings;
  settings.spp = 32;
  const LightmapEstimate estimate = CpuReferenceIntegrator(scene).bake(gbuffer, settings);
  EXPECT_EQ(estimate.nonfinite_samples, 0u);
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) EXPECT_TRUE(is_finite(estimate.mean_total(i)));
}

// The query under the coplanar check: two coincident quads facing opposite ways are hit at one
// distance, and a predicate that accepts only one of them must find it whichever Embree's kernels
// would report as the closest (a closest-hit query fails one of the two cases on any CPU).
TEST(GeometryWarnings, AnyHitWhereOffersEveryEquidistantHit) {
  Scene scene;
  const uint32_t grey = add_material(scene, {0.5f, 0.5f, 0.5f});
  add_quad(scene, {0, 0, 1}, {1, 0, 0}, {0, 0, -1}, grey);  // normal +y
  add_quad(scene, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}, grey);   // normal -y, same square
  EmbreeScene embree(scene);
  const Vec3 origin{0.3f, 1.0f, 0.6f}, down{0, -1, 0};
  for (const float facing : {1.0f, -1.0f}) {
    int offered = 0;
    EXPECT_TRUE(embree.any_hit_where(origin, down, 2.0f, [&](const Hit& hit) {
      ++offered;
      EXPECT_NEAR(hit.distance, 1.0f, 1e-6f);
      return hit.geometric_normal.y == facing;
    })) << "facing " << facing;
    EXPECT_GE(offered, 1);
  }
  // Rejecting everything sees one triangle of each quad (possibly more than once: spatial splits).
  std::set<uint32_t> seen;
  EXPECT_FALSE(embree.any_hit_where(origin, down, 2.0f, [&](const Hit& hit) { return seen.insert(hit.triangle), false; }));
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_LT(*seen.begin(), 2u);
  EXPECT_GE(*seen.rbegin(), 2u);
  EXPECT_FALSE(embree.any_hit_where(origin, down, 0.5f, [](const Hit&) { return true; }));  // out of reach
}

}  // namespace
}  // namespace exitance
