// Generated lightmap UVs (bake/uvgen, issue 13) on closed primitives and hostile meshes: finite UVs in
// [0,1], few charts on smooth shapes, no two charts within 2 texels of each other at the resolution
// the atlas layout gives the mesh, bounded distortion, good utilization, bit-identical reruns.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <set>
#include <string>

#include "exitance/bake/layout/atlas_layout.h"
#include "exitance/bake/uvgen/lightmap_uv_generation.h"
#include "exitance/bake/uvgen/scene_uv_generation.h"

namespace exitance {
namespace {

constexpr double kPi = std::numbers::pi;

struct Mesh {
  std::vector<Vec3> positions;
  std::vector<uint32_t> indices;
  void triangle(Vec3 a, Vec3 b, Vec3 c) {  // three vertices of its own, as exporters split them
    const uint32_t base = uint32_t(positions.size());
    positions.insert(positions.end(), {a, b, c});
    indices.insert(indices.end(), {base, base + 1, base + 2});
  }
  void quad(Vec3 a, Vec3 b, Vec3 c, Vec3 d) { triangle(a, b, c), triangle(a, c, d); }
};

Mesh cube(Vec3 origin = {0, 0, 0}) {
  Mesh m;
  auto p = [&](float x, float y, float z) { return origin + Vec3{x, y, z}; };
  m.quad(p(0, 0, 0), p(0, 1, 0), p(1, 1, 0), p(1, 0, 0));  // -z
  m.quad(p(0, 0, 1), p(1, 0, 1), p(1, 1, 1), p(0, 1, 1));  // +z
  m.quad(p(0, 0, 0), p(1, 0, 0), p(1, 0, 1), p(0, 0, 1));  // -y
  m.quad(p(0, 1, 0), p(0, 1, 1), p(1, 1, 1), p(1, 1, 0));  // +y
  m.quad(p(0, 0, 0), p(0, 0, 1), p(0, 1, 1), p(0, 1, 0));  // -x
  m.quad(p(1, 0, 0), p(1, 1, 0), p(1, 1, 1), p(1, 0, 1));  // +x
  return m;
}

// A (u, v) grid of vertices with a seam column duplicated, as UV-mapped exports have; quads split
// into two triangles (dropping the ones collapsed at a pole).
template <class Surface>
Mesh parametric(int nu, int nv, Surface surface) {
  Mesh m;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) m.positions.push_back(surface(2 * kPi * i / nu, double(j) / nv));
  auto at = [&](int i, int j) { return uint32_t(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
  return m;
}

Mesh uv_sphere(int nu = 32, int nv = 16) {
  return parametric(nu, nv, [](double u, double v) {
    const double theta = kPi * (1 - v);
    return Vec3{float(std::sin(theta) * std::cos(u)), float(std::cos(theta)), float(std::sin(theta) * std::sin(u))};
  });
}

Mesh torus(int nu = 48, int nv = 24) {
  return parametric(nu, nv, [](double u, double v) {
    const double w = 2 * kPi * v, r = 1 + 0.35 * std::cos(w);
    return Vec3{float(r * std::cos(u)), float(0.35 * std::sin(w)), float(-r * std::sin(u))};
  });
}

Mesh cylinder(int segments = 24) {
  Mesh m = parametric(segments, 4, [](double u, double v) {
    return Vec3{float(std::cos(u)), float(2 * v), float(-std::sin(u))};
  });
  for (int i = 0; i < segments; ++i) {  // caps, vertices of their own
    const double a = 2 * kPi * i / segments, b = 2 * kPi * (i + 1) / segments;
    m.triangle({0, 2, 0}, {float(std::cos(a)), 2, float(-std::sin(a))}, {float(std::cos(b)), 2, float(-std::sin(b))});
    m.triangle({0, 0, 0}, {float(std::cos(b)), 0, float(-std::sin(b))}, {float(std::cos(a)), 0, float(-std::sin(a))});
  }
  return m;
}

Mesh non_manifold_fin() {  // three triangles on one edge, plus a quad around them
  Mesh m;
  m.triangle({0, 0, 0}, {1, 0, 0}, {0.5f, 1, 0});
  m.triangle({1, 0, 0}, {0, 0, 0}, {0.5f, -1, 0});
  m.triangle({0, 0, 0}, {1, 0, 0}, {0.5f, 0, 1});
  m.quad({2, 0, 0}, {3, 0, 0}, {3, 1, 0}, {2, 1, 0});
  return m;
}

Mesh with_degenerate_triangles() {
  Mesh m;
  m.quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0});
  m.triangle({0, 0, 0}, {1, 0, 0}, {0.5f, 0, 0});      // collinear, on the quad's edge
  m.triangle({5, 5, 5}, {5, 5, 5}, {5, 5, 5});         // a point, far from everything
  m.triangle({0, 1, 0}, {1, 1, 0}, {1, 1, 0});         // a repeated vertex
  m.triangle({2, 0, 0}, {3, 0, 0}, {2.5f, 1e-7f, 0});  // a sliver
  return m;
}

Mesh two_cubes() {
  Mesh m = cube();
  const Mesh second = cube({4, 0, 0});
  const uint32_t base = uint32_t(m.positions.size());
  m.positions.insert(m.positions.end(), second.positions.begin(), second.positions.end());
  for (uint32_t i : second.indices) m.indices.push_back(base + i);
  return m;
}

constexpr float kDensity = 32;  // texels per unit for the overlap checks
constexpr int kMaxPage = 2048, kPadding = 2;

GeneratedUvs generate(const Mesh& mesh) {
  UvGenerationSettings settings;
  settings.texels_per_unit = kDensity;
  settings.max_side_texels = kMaxPage - 2 * kPadding;
  return generate_lightmap_uvs(mesh.positions, mesh.indices, settings);
}

// The mesh as a one-instance scene with the generated UVs, laid out as bake lays it out.
struct LaidOut {
  Scene scene;
  AtlasLayout layout;
};

LaidOut lay_out(const Mesh& mesh, const GeneratedUvs& uvs) {
  LaidOut out;
  Scene& s = out.scene;
  s.materials.push_back(Material{});
  for (size_t t = 0; t < mesh.indices.size() / 3; ++t) {
    for (size_t k = 0; k < 3; ++k) {
      s.positions.push_back(mesh.positions[mesh.indices[3 * t + k]]);
      s.normals.push_back({0, 0, 1});
      s.uv0.push_back({});
      s.lightmap_uv.push_back(uvs.corner_uv[3 * t + k]);
    }
    s.triangle_material.push_back(0);
    s.triangle_instance.push_back(0);
  }
  Instance instance;
  instance.node = 0;
  instance.mesh = 0;
  instance.triangle_count = uint32_t(s.triangle_count());
  s.instances.push_back(instance);
  AtlasSettings atlas;
  atlas.texel_density = kDensity;
  atlas.max_page = kMaxPage;
  atlas.padding = kPadding;
  Diagnostics diagnostics;
  out.layout = layout_lightmap_atlas(s, atlas, "test.gltf", diagnostics);
  return out;
}

// Separating-axis test of a triangle against the texel [x, x+1] x [y, y+1] (touching counts).
bool touches_texel(const std::array<Vec2, 3>& p, int x, int y) {
  auto separated = [&](double ax, double ay) {
    double lo = 1e300, hi = -1e300;
    for (const Vec2& q : p) lo = std::min(lo, ax * q.x + ay * q.y), hi = std::max(hi, ax * q.x + ay * q.y);
    double box_lo = 1e300, box_hi = -1e300;
    for (int dx = 0; dx < 2; ++dx)
      for (int dy = 0; dy < 2; ++dy) {
        const double d = ax * (x + dx) + ay * (y + dy);
        box_lo = std::min(box_lo, d), box_hi = std::max(box_hi, d);
      }
    return hi < box_lo || lo > box_hi;
  };
  if (separated(1, 0) || separated(0, 1)) return false;
  for (int k = 0; k < 3; ++k) {
    const Vec2 e = p[size_t(k + 1) % 3] - p[size_t(k)];
    if (separated(-e.y, e.x)) return false;
  }
  return true;
}

struct OverlapCount {
  size_t shared_texels = 0;     // conservatively covered by two charts
  size_t gutter_violations = 0;  // covered texels with another chart's texel within 2 texels
};

OverlapCount count_overlaps(const LaidOut& laid, const GeneratedUvs& uvs) {
  const InstanceRect& r = laid.layout.rects[0];
  const auto [pw, ph] = laid.layout.page_sizes[size_t(r.page)];
  constexpr int32_t kEmpty = -1, kShared = -2;
  std::vector<int32_t> owner(size_t(pw) * size_t(ph), kEmpty);
  OverlapCount count;
  for (size_t t = 0; t < laid.scene.triangle_count(); ++t) {
    std::array<Vec2, 3> p;
    for (size_t k = 0; k < 3; ++k) {
      const Vec2 uv = laid.scene.lightmap_uv[3 * t + k];
      p[k] = {(uv.x * r.scale_offset[0] + r.scale_offset[2]) * float(pw), (uv.y * r.scale_offset[1] + r.scale_offset[3]) * float(ph)};
    }
    const int x0 = std::max(0, int(std::floor(std::min({p[0].x, p[1].x, p[2].x})))), x1 = std::min(pw - 1, int(std::floor(std::max({p[0].x, p[1].x, p[2].x}))));
    const int y0 = std::max(0, int(std::floor(std::min({p[0].y, p[1].y, p[2].y})))), y1 = std::min(ph - 1, int(std::floor(std::max({p[0].y, p[1].y, p[2].y}))));
    const int32_t chart = int32_t(uvs.triangle_chart[t]);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        if (!touches_texel(p, x, y)) continue;
        int32_t& o = owner[size_t(y) * size_t(pw) + size_t(x)];
        if (o == kEmpty) o = chart;
        else if (o != chart && o != kShared) o = kShared, ++count.shared_texels;
      }
  }
  for (int y = 0; y < ph; ++y)
    for (int x = 0; x < pw; ++x) {
      const int32_t o = owner[size_t(y) * size_t(pw) + size_t(x)];
      if (o < 0) continue;
      bool violated = false;
      for (int dy = -2; dy <= 2 && !violated; ++dy)
        for (int dx = -2; dx <= 2 && !violated; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= pw || ny >= ph) continue;
          const int32_t n = owner[size_t(ny) * size_t(pw) + size_t(nx)];
          violated = n != kEmpty && n != o;
        }
      count.gutter_violations += violated;
    }
  return count;
}

void expect_valid_uvs(const Mesh& mesh, const GeneratedUvs& uvs) {
  ASSERT_EQ(uvs.corner_uv.size(), mesh.indices.size());
  for (const Vec2& uv : uvs.corner_uv) {
    ASSERT_TRUE(std::isfinite(uv.x) && std::isfinite(uv.y));
    ASSERT_GE(uv.x, 0.0f);
    ASSERT_LE(uv.x, 1.0f);
    ASSERT_GE(uv.y, 0.0f);
    ASSERT_LE(uv.y, 1.0f);
  }
  const OverlapCount overlaps = count_overlaps(lay_out(mesh, uvs), uvs);
  EXPECT_EQ(overlaps.shared_texels, 0u);
  EXPECT_EQ(overlaps.gutter_violations, 0u);
  EXPECT_TRUE(uvs.stats.gutter_holds);
}

void print_stats(const char* name, const UvGenerationStats& s) {
  std::printf("%-12s triangles %6zu charts %3zu (lscm %zu, planar %zu) utilization %.3f area distortion max %.3f mean %.3f "
              "angle distortion max %.3f mean %.3f packed %dx%d\n",
              name, s.triangles, s.charts, s.lscm_charts, s.planar_charts, s.utilization, s.max_area_distortion,
              s.mean_area_distortion, s.max_angle_distortion, s.mean_angle_distortion, s.packed_width, s.packed_height);
}

struct Shape {
  const char* name;
  Mesh mesh;
  size_t max_charts;
  double min_utilization;
  double max_mean_area_distortion;
};

TEST(LightmapUvGeneration, ClosedPrimitivesGiveFewChartsAndNoOverlap) {
  // At 32 texels per unit the 3.1-texel gaps cost much of a small chart, and a torus's halves are
  // ~200-degree arches (bench/results/uvgen.md): the bounds are what the layout search achieves here
  // (cube 0.848, sphere 0.689, cylinder 0.829, torus 0.619) less about three texel rows of the
  // packed rectangle (~0.02), for LSCM round-off moving a mask texel on another machine; the torus
  // at the 60 % issue 13 asks for.
  const Shape shapes[] = {{"cube", cube(), 6, 0.83, 1.01},
                          {"uv sphere", uv_sphere(), 4, 0.67, 1.3},
                          {"cylinder", cylinder(), 6, 0.81, 1.01},
                          {"torus", torus(), 6, 0.60, 1.15}};
  for (const Shape& shape : shapes) {
    SCOPED_TRACE(shape.name);
    const GeneratedUvs uvs = generate(shape.mesh);
    print_stats(shape.name, uvs.stats);
    expect_valid_uvs(shape.mesh, uvs);
    EXPECT_LE(uvs.stats.charts, shape.max_charts);
    EXPECT_GE(uvs.stats.utilization, shape.min_utilization);
    EXPECT_LE(uvs.stats.mean_area_distortion, shape.max_mean_area_distortion);
    EXPECT_EQ(uvs.stats.stretched_charts, 0u);
  }
}

// The layout search (other first seeds, halved arches) keeps a layout only when it fills more of
// the packed rectangle: never below the first layout, and above it on the torus.
TEST(LightmapUvGeneration, LayoutSearchNeverFillsLess) {
  const std::pair<const char*, Mesh> meshes[] = {{"uv sphere", uv_sphere()}, {"cylinder", cylinder()}, {"torus", torus()}};
  for (const auto& [name, mesh] : meshes) {
    SCOPED_TRACE(name);
    UvGenerationSettings settings;
    settings.texels_per_unit = kDensity;
    settings.max_side_texels = kMaxPage - 2 * kPadding;
    const GeneratedUvs searched = generate_lightmap_uvs(mesh.positions, mesh.indices, settings);
    settings.layout_search_max_triangles = 0;
    const GeneratedUvs first = generate_lightmap_uvs(mesh.positions, mesh.indices, settings);
    EXPECT_GE(searched.stats.utilization, first.stats.utilization);
    if (std::string(name) == "torus") {
      EXPECT_GT(searched.stats.utilization, first.stats.utilization + 0.03);
    }
  }
}

TEST(LightmapUvGeneration, HostileMeshesGiveValidSeparatedCharts) {
  const Shape shapes[] = {{"non-manifold", non_manifold_fin(), 5, 0, 2},
                          {"degenerate", with_degenerate_triangles(), 5, 0, 2},
                          {"two cubes", two_cubes(), 12, 0.81, 1.01}};
  for (const Shape& shape : shapes) {
    SCOPED_TRACE(shape.name);
    const GeneratedUvs uvs = generate(shape.mesh);
    print_stats(shape.name, uvs.stats);
    expect_valid_uvs(shape.mesh, uvs);
    EXPECT_LE(uvs.stats.charts, shape.max_charts);
    EXPECT_GE(uvs.stats.utilization, shape.min_utilization);
  }
}

TEST(LightmapUvGeneration, DegenerateFacesAreFoldedOrGetAPointChart) {
  const GeneratedUvs uvs = generate(with_degenerate_triangles());
  EXPECT_EQ(uvs.stats.degenerate_triangles, 3u);
  // The isolated point triangle has a chart of its own; the two others sit on the quad's chart.
  EXPECT_EQ(uvs.triangle_chart[2], uvs.triangle_chart[0]);
  EXPECT_EQ(uvs.triangle_chart[4], uvs.triangle_chart[0]);
  EXPECT_NE(uvs.triangle_chart[3], uvs.triangle_chart[0]);
}

TEST(LightmapUvGeneration, SplitVerticesAreWeldedIntoOneChartPerFace) {
  // Every triangle of the sphere with vertices of its own: still the same few charts.
  const Mesh shared = uv_sphere(24, 12);
  Mesh split;
  for (size_t t = 0; t < shared.indices.size(); t += 3)
    split.triangle(shared.positions[shared.indices[t]], shared.positions[shared.indices[t + 1]],
                   shared.positions[shared.indices[t + 2]]);
  EXPECT_EQ(generate(split).stats.charts, generate(shared).stats.charts);
}

TEST(LightmapUvGeneration, SameInputGivesBitIdenticalUvs) {
  const Mesh mesh = torus();
  const GeneratedUvs a = generate(mesh), b = generate(mesh);
  ASSERT_EQ(a.corner_uv.size(), b.corner_uv.size());
  EXPECT_EQ(std::memcmp(a.corner_uv.data(), b.corner_uv.data(), a.corner_uv.size() * sizeof(Vec2)), 0);
}

TEST(LightmapUvGeneration, SmallPageLowersTheDensityInsteadOfBreakingTheGutter) {
  UvGenerationSettings settings;
  settings.texels_per_unit = 1000;
  settings.max_side_texels = 128;
  const Mesh mesh = uv_sphere();
  const GeneratedUvs uvs = generate_lightmap_uvs(mesh.positions, mesh.indices, settings);
  EXPECT_TRUE(uvs.stats.gutter_holds);
  EXPECT_LE(std::max(uvs.stats.packed_width, uvs.stats.packed_height), 128);
  EXPECT_LT(uvs.stats.texels_per_unit, 1000);
}

TEST(LightmapUvGeneration, IndexOutOfRangeIsRefused) {
  const std::vector<Vec3> positions{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<uint32_t> indices{0, 1, 3};
  EXPECT_THROW(generate_lightmap_uvs(positions, indices, {}), std::invalid_argument);
}

// The scene path bake takes: two instances of one mesh at different scales share its UVs, and the
// smaller one still keeps charts 2 texels apart at the rectangle the layout gives it.
TEST(SceneUvGeneration, InstancesShareTheMeshUvsAndTheSmallestKeepsTheGutter) {
  const Mesh mesh = torus(32, 16);
  MeshWithoutLightmapUvs request;
  request.mesh = 0;
  request.name = "Torus";
  request.positions = mesh.positions;
  request.indices = mesh.indices;
  Scene scene;
  scene.materials.push_back(Material{});
  for (uint32_t i = 0; i < 2; ++i) {
    const float scale = i == 0 ? 1.0f : 0.25f;
    Instance instance;
    instance.node = int(i);
    instance.mesh = 0;
    instance.first_triangle = uint32_t(scene.triangle_count());
    auto& placement = request.instances.emplace_back();
    placement.instance = i;
    for (size_t t = 0; t < mesh.indices.size() / 3; ++t) {
      for (size_t k = 0; k < 3; ++k) {
        scene.positions.push_back(mesh.positions[mesh.indices[3 * t + k]] * scale);
        scene.normals.push_back({0, 0, 1});
        scene.uv0.push_back({});
        scene.lightmap_uv.push_back({});
        placement.corners.push_back(uint32_t(3 * t + k));
      }
      scene.triangle_material.push_back(0);
      scene.triangle_instance.push_back(i);
    }
    instance.triangle_count = uint32_t(scene.triangle_count()) - instance.first_triangle;
    scene.instances.push_back(instance);
  }
  const std::vector<MeshUvReport> reports = generate_missing_lightmap_uvs(scene, {request}, kDensity, kMaxPage - 2 * kPadding, {});
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports[0].name, "Torus");
  const size_t per_instance = mesh.indices.size();
  for (size_t c = 0; c < per_instance; ++c) {
    EXPECT_EQ(scene.lightmap_uv[c].x, scene.lightmap_uv[per_instance + c].x);
    EXPECT_EQ(scene.lightmap_uv[c].y, scene.lightmap_uv[per_instance + c].y);
  }
  // Packed for the quarter-size instance: 8 texels per unit, not 32.
  EXPECT_NEAR(reports[0].stats.texels_per_unit, kDensity * 0.25, 1e-3);
}

}  // namespace
}  // namespace exitance
