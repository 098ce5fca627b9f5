// The open-city sample (samples/open_city.cpp) as the baker reads it: it imports without
// warnings, is as large as the bench suite needs (≥ 400 k triangles in ≥ 50 instances), its
// instances share their meshes' lightmap UVs, and the atlas gives each its own rectangle.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <tuple>

#include <unistd.h>

#include "exitance/bake/import/gltf_import.h"
#include "exitance/bake/layout/atlas_layout.h"
#include "sample_scenes.h"

namespace exitance {
namespace {

TEST(OpenCitySample, ImportsAsInstancedMeshesWithTheirOwnAtlasRectangles) {
  samples::SceneBuilder builder;
  samples::buildOpenCity(builder);
  const auto dir = std::filesystem::temp_directory_path() / ("open_city_sample_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "open_city.gltf").string();
  builder.write(path);
  Diagnostics diagnostics;
  const Scene scene = import_gltf(path, ImportOptions{}, diagnostics);
  std::filesystem::remove_all(dir);

  EXPECT_TRUE(diagnostics.warnings.empty()) << diagnostics.warnings.front();
  EXPECT_EQ(scene.triangle_count(), builder.triangleCount());
  EXPECT_GE(scene.triangle_count(), 400000u);
  EXPECT_GE(scene.instances.size(), 50u);
  ASSERT_EQ(scene.lights.size(), 1u);
  EXPECT_EQ(scene.lights[0].type, PunctualLight::Type::Directional);

  // Every instance of a mesh carries that mesh's TEXCOORD_1, bit for bit.
  std::map<int, const Instance*> first_of_mesh;
  size_t shared = 0;
  for (const Instance& instance : scene.instances) {
    const auto found = first_of_mesh.try_emplace(instance.mesh, &instance);
    if (found.second) continue;
    const Instance& first = *found.first->second;
    ASSERT_EQ(instance.triangle_count, first.triangle_count) << instance.name;
    for (uint32_t c = 0; c < 3 * instance.triangle_count; ++c) {
      const Vec2 a = scene.lightmap_uv[3 * size_t(first.first_triangle) + c];
      const Vec2 b = scene.lightmap_uv[3 * size_t(instance.first_triangle) + c];
      ASSERT_TRUE(a.x == b.x && a.y == b.y) << instance.name << " corner " << c;
    }
    ++shared;
  }
  EXPECT_GE(shared, 50u);  // instances beyond each mesh's first

  AtlasSettings settings;
  settings.texel_density = 0.5f;
  Diagnostics layout_diagnostics;
  const AtlasLayout layout = layout_lightmap_atlas(scene, settings, path, layout_diagnostics);
  EXPECT_TRUE(layout_diagnostics.warnings.empty());
  ASSERT_EQ(layout.rects.size(), scene.instances.size());
  std::set<std::tuple<int, int, int>> corners;
  for (const InstanceRect& r : layout.rects) corners.insert({r.page, r.x, r.y});
  EXPECT_EQ(corners.size(), layout.rects.size());
}

}  // namespace
}  // namespace exitance
