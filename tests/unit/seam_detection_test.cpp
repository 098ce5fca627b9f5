// Seam detection (runtime/include/exitance/runtime/bundle/seam_detection.h) on primitives: a cube of six charts has only hard
// edges (nothing stitched), a cylinder side with one UV cut has exactly that cut, a sphere with
// generated UVs has seams between its charts.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "exitance/runtime/bundle/seam_detection.h"
#include "exitance/bake/uvgen/lightmap_uv_generation.h"

namespace exitance {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kPage = 256;

// One instance, its triangles' corners as given, its rectangle the whole 256 x 256 page.
struct SingleInstance {
  Scene scene;
  AtlasLayout layout;

  SingleInstance() {
    layout.page_sizes = {{kPage, kPage}};
    layout.rects.push_back(InstanceRect{});
  }
  void corner(Vec3 p, Vec3 n, Vec2 uv) {
    scene.positions.push_back(p);
    scene.normals.push_back(normalize(n));
    scene.lightmap_uv.push_back(uv);
  }
  void finish() {
    Instance instance;
    instance.triangle_count = uint32_t(scene.positions.size() / 3);
    scene.instances = {instance};
    scene.triangle_instance.assign(instance.triangle_count, 0);
    scene.triangle_material.assign(instance.triangle_count, 0);
  }
};

// A unit cube, each face its own chart in a 3 x 2 grid of UV cells, flat normals.
SingleInstance cube_of_six_charts() {
  SingleInstance mesh;
  const Vec3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  int face = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (float sign : {-1.0f, 1.0f}) {
      const Vec3 n = axes[axis] * sign, u = axes[(axis + 1) % 3], v = axes[(axis + 2) % 3] * sign;
      const Vec3 c = n * 0.5f;
      const Vec3 corners[4] = {c - u * 0.5f - v * 0.5f, c + u * 0.5f - v * 0.5f, c + u * 0.5f + v * 0.5f,
                               c - u * 0.5f + v * 0.5f};
      const float u0 = float(face % 3) / 3 + 0.02f, v0 = float(face / 3) / 2 + 0.02f, size = 0.25f;
      const Vec2 uvs[4] = {{u0, v0}, {u0 + size, v0}, {u0 + size, v0 + size}, {u0, v0 + size}};
      for (int k : {0, 1, 2, 0, 2, 3}) mesh.corner(corners[k], n, uvs[k]);
      ++face;
    }
  mesh.finish();
  return mesh;
}

// The side of a cylinder of radius 1, height 2, `segments` around and `rows` up, with smooth
// normals and lightmap UVs (angle / 2 pi, height / 2) scaled into [0.05, 0.95]: one cut where the
// angle wraps from 1 back to 0.
SingleInstance cylinder_side(int segments, int rows) {
  SingleInstance mesh;
  auto point = [](int i, int j, int segments_, int rows_) {
    const double a = 2 * kPi * i / segments_;
    return Vec3{float(std::cos(a)), float(2.0 * j / rows_), float(-std::sin(a))};
  };
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < segments; ++i) {
      const int ci[4] = {i, i + 1, i + 1, i}, cj[4] = {j, j, j + 1, j + 1};
      for (int k : {0, 1, 2, 0, 2, 3}) {
        const Vec3 p = point(ci[k], cj[k], segments, rows);
        mesh.corner(p, {p.x, 0, p.z},
                    {0.05f + 0.9f * float(ci[k]) / float(segments), 0.05f + 0.9f * float(cj[k]) / float(rows)});
      }
    }
  mesh.finish();
  return mesh;
}

TEST(SeamDetection, CubeOfSixChartsHasOnlyHardEdges) {
  const SingleInstance cube = cube_of_six_charts();
  // The 12 edges are UV cuts (each face has its own chart), but their normals differ by 90°.
  EXPECT_TRUE(find_lightmap_seams(cube.scene, cube.layout).empty());
  // With a normal tolerance above 90° all 12 would be stitched: the test sees them as cuts.
  SeamDetectionSettings lenient;
  lenient.max_normal_angle_degrees = 91;
  EXPECT_EQ(find_lightmap_seams(cube.scene, cube.layout, lenient).size(), 12u);
}

TEST(SeamDetection, CylinderSideHasItsOneCut) {
  const int segments = 24, rows = 4;
  const SingleInstance cylinder = cylinder_side(segments, rows);
  const std::vector<SeamEdge> seams = find_lightmap_seams(cylinder.scene, cylinder.layout);
  ASSERT_EQ(seams.size(), size_t(rows));
  const float left = 0.05f * kPage, right = 0.95f * kPage;
  for (const SeamEdge& seam : seams) {
    // One side on the chart's left border, the other on its right, at the same heights.
    for (int k = 0; k < 2; ++k) {
      const float xa = seam.side_a[k].x, xb = seam.side_b[k].x;
      EXPECT_NEAR(std::min(xa, xb), left, 1e-3);
      EXPECT_NEAR(std::max(xa, xb), right, 1e-3);
      EXPECT_NEAR(seam.side_a[k].y, seam.side_b[k].y, 1e-3);
    }
    EXPECT_EQ(seam.page, 0);
  }
}

TEST(SeamDetection, SphereWithGeneratedUvsHasSeamsBetweenItsCharts) {
  // A UV sphere with shared vertices, its UVs generated (charts by normal cone, LSCM).
  const int nu = 32, nv = 16;
  std::vector<Vec3> positions;
  std::vector<uint32_t> indices;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const double theta = kPi * (1 - double(j) / nv), phi = 2 * kPi * i / nu;
      positions.push_back({float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
                           float(std::sin(theta) * std::sin(phi))});
    }
  auto at = [&](int i, int j) { return uint32_t(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i)
      indices.insert(indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
  const GeneratedUvs uvs = generate_lightmap_uvs(positions, indices, UvGenerationSettings{});
  ASSERT_GE(uvs.stats.charts, 2u);
  SingleInstance sphere;
  for (size_t c = 0; c < indices.size(); ++c) {
    const Vec3 p = positions[indices[c]];
    sphere.corner(p, p, uvs.corner_uv[c]);
  }
  sphere.finish();
  const std::vector<SeamEdge> seams = find_lightmap_seams(sphere.scene, sphere.layout);
  EXPECT_GT(seams.size(), 0u);
  // Every seam joins two charts: its sides lie on triangles of different charts, which the UVs
  // show as sides apart in the atlas (more than the 3-texel gutter the packing leaves).
  for (const SeamEdge& seam : seams) {
    const float apart = std::hypot(seam.side_a[0].x - seam.side_b[0].x, seam.side_a[0].y - seam.side_b[0].y) +
                        std::hypot(seam.side_a[1].x - seam.side_b[1].x, seam.side_a[1].y - seam.side_b[1].y);
    EXPECT_GT(apart, 1.0f);
  }
}

}  // namespace
}  // namespace exitance
