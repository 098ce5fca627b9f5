// The bake's unocclude stage (bake/raster/unocclude.cpp) skips texels whose sideways rays can meet
// nothing, found by one point query instead of 8 rays. The skip must change nothing: on the sample
// scenes the stage moves exactly the texels, to exactly the positions, that unocclude_texel moves
// when every texel traces its rays. And EmbreeScene::any_triangle_within, the query it rests on,
// against closed-form distances.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "exitance/bake/command/bake_stages.h"
#include "exitance/bake/raster/unocclude.h"
#include "exitance/runtime/embree_scene.h"
#include "exitance/runtime/unocclude_texel.h"
#include "support/test_scenes.h"

namespace exitance {
namespace {

bool same_bits(Vec3 a, Vec3 b) { return std::memcmp(&a, &b, sizeof(Vec3)) == 0; }

class UnoccludeStage : public ::testing::TestWithParam<const char*> {};

TEST_P(UnoccludeStage, MovesTheSameTexelsAsTracingEveryTexel) {
  const std::string path = std::string(EXITANCE_SAMPLE_DIR "/") + GetParam() + ".gltf";
  // The offline stages up to the raster, as bake runs them, at most ~1 M texels.
  BakeOptions options;
  options.input = path;
  options.atlas.max_total_texels = size_t(1) << 20;
  Diagnostics diagnostics;
  std::vector<MeshWithoutLightmapUvs> without_lightmap_uvs;
  Scene scene = import_stage(options, diagnostics, without_lightmap_uvs);
  uv_generation_stage(scene, without_lightmap_uvs, options, diagnostics);
  const AtlasLayout layout = layout_stage(scene, options, diagnostics);
  const TexelGBuffer raster = raster_stage(scene, layout, options, diagnostics);
  const EmbreeScene embree(scene);

  TexelGBuffer staged = raster;
  const size_t moved = unocclude_texels(embree, staged).moved;

  TexelGBuffer traced = raster;
  const ClosestHitQuery closest_hit = [&](const Vec3& origin, const Vec3& direction, float t_max) {
    const Hit hit = embree.intersect(origin, direction, t_max);
    return OccluderHit{hit.found, hit.distance, hit.geometric_normal};
  };
  size_t traced_moved = 0;
  for (LiveTexel& texel : traced.texels) traced_moved += unocclude_texel(texel, embree.extent(), closest_hit) ? 1 : 0;

  EXPECT_EQ(moved, traced_moved);
  ASSERT_EQ(staged.texels.size(), traced.texels.size());
  size_t differ = 0;
  for (size_t i = 0; i < staged.texels.size(); ++i)
    if (!same_bits(staged.texels[i].position, traced.texels[i].position) && ++differ <= 5)
      ADD_FAILURE() << GetParam() << ": texel " << i << " ends at " << staged.texels[i].position.x << ", "
                    << staged.texels[i].position.y << ", " << staged.texels[i].position.z << " instead of "
                    << traced.texels[i].position.x << ", " << traced.texels[i].position.y << ", "
                    << traced.texels[i].position.z;
  EXPECT_EQ(differ, 0u);
  std::printf("%s: %zu live texels, %zu moved by unocclude\n", GetParam(), staged.texels.size(), moved);
}

// Scenes where unocclude moves texels (rooms, the building's walls on floors) and the courtyard.
INSTANTIATE_TEST_SUITE_P(Samples, UnoccludeStage, ::testing::Values("cornell_room", "ajar_room", "building", "courtyard"));

TEST(AnyTriangleWithin, FindsTrianglesByTheirClosestPoint) {
  Scene scene;
  const uint32_t m = testing::add_material(scene, {0.5f, 0.5f, 0.5f});
  testing::add_quad(scene, {0, 0, 0}, {4, 0, 0}, {0, 0, 4}, m);  // the square [0, 4]² at y = 0
  const EmbreeScene embree(scene);
  auto any = [](uint32_t, const Vec3*) { return true; };
  auto none = [](uint32_t, const Vec3*) { return false; };
  EXPECT_TRUE(embree.any_triangle_within({2, 1, 2}, 1.01f, any));   // 1 above the face
  EXPECT_FALSE(embree.any_triangle_within({2, 1, 2}, 0.99f, any));
  EXPECT_FALSE(embree.any_triangle_within({2, 1, 2}, 10.0f, none));  // found, but not relevant
  EXPECT_TRUE(embree.any_triangle_within({7, 0, 8}, 5.01f, any));    // 5 from the corner (4, 0, 4)
  EXPECT_FALSE(embree.any_triangle_within({7, 0, 8}, 4.99f, any));
  // The predicate sees the triangle's own corners.
  size_t calls = 0;
  EXPECT_FALSE(embree.any_triangle_within({2, 0, 2}, 0.5f, [&](uint32_t t, const Vec3* corners) {
    ++calls;
    EXPECT_TRUE(same_bits(corners[0], scene.positions[size_t(t) * 3]));
    return false;
  }));
  EXPECT_GT(calls, 0u);
}

}  // namespace
}  // namespace exitance
