// Unit tests of the offline stage's geometry: texel/triangle clipping, atlas packing,
// the G-buffer raster and the sampling helpers it relies on.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "exitance/bake/layout/atlas_layout.h"
#include "exitance/bake/raster/cell_rejection.h"
#include "exitance/runtime/bundle/lightmap_assembly.h"
#include "exitance/bake/raster/texel_raster.h"
#include "exitance/runtime/distribution_1d.h"
#include "exitance/runtime/environment_sampler.h"
#include "exitance/common/ray_offset.h"
#include "exitance/common/rng.h"
#include "exitance/common/sampling.h"
#include "support/test_scenes.h"

namespace exitance {
namespace {

TEST(TexelClipping, FullPartialAndEmptyCoverage) {
  const Vec2 big[3] = {{-10, -10}, {10, -10}, {0, 10}};
  Vec2 c;
  EXPECT_NEAR(clipped_texel_coverage(big, 0, 0, c), 1.0f, 1e-6f);
  EXPECT_NEAR(c.x, 0.5f, 1e-6f);
  // Lower-left half of the texel (both windings give the same area).
  const Vec2 half_ccw[3] = {{0, 0}, {1, 0}, {0, 1}};
  const Vec2 half_cw[3] = {{0, 0}, {0, 1}, {1, 0}};
  EXPECT_NEAR(clipped_texel_coverage(half_ccw, 0, 0, c), 0.5f, 1e-6f);
  EXPECT_NEAR(c.x, 1.0f / 3.0f, 1e-6f);
  EXPECT_NEAR(clipped_texel_coverage(half_cw, 0, 0, c), 0.5f, 1e-6f);
  EXPECT_EQ(clipped_texel_coverage(half_ccw, 3, 3, c), 0.0f);
}

// The raster skips the cells CellRejection rejects: the clip must give every one of them no area,
// for large and thin triangles anywhere on a 2048 page (where float rounding is coarsest), and the
// rejection must still take most of a thin diagonal triangle's bounding box.
TEST(TexelClipping, RejectedCellsGetNoCoverage) {
  Pcg32 rng = pcg_init(42, 0, 0);
  size_t rejected = 0, cells = 0;
  for (int n = 0; n < 3000; ++n) {
    Vec2 tri[3];
    const Vec2 base{2040.0f * pcg_uniform(rng), 2040.0f * pcg_uniform(rng)};
    const float size = n % 3 == 0 ? 0.5f : n % 3 == 1 ? 8.0f : 200.0f;
    for (Vec2& v : tri) v = {base.x + size * pcg_uniform(rng), base.y + size * pcg_uniform(rng)};
    if (n % 2) tri[2] = tri[0] + (tri[1] - tri[0]) * pcg_uniform(rng) + Vec2{0.02f, -0.01f};  // slivers
    const CellRejection outside(tri);
    const int x0 = int(std::floor(std::min({tri[0].x, tri[1].x, tri[2].x}))), x1 = int(std::ceil(std::max({tri[0].x, tri[1].x, tri[2].x})));
    const int y0 = int(std::floor(std::min({tri[0].y, tri[1].y, tri[2].y}))), y1 = int(std::ceil(std::max({tri[0].y, tri[1].y, tri[2].y})));
    for (int y = y0; y <= y1 && cells < 4000000; ++y)
      for (int x = x0; x <= x1; ++x) {
        ++cells;
        if (!outside.rejects(x, y)) continue;
        ++rejected;
        Vec2 centroid;
        ASSERT_EQ(clipped_texel_coverage(tri, x, y, centroid), 0.0f) << "triangle " << n << ", cell " << x << ", " << y;
      }
  }
  EXPECT_GT(rejected, cells / 4);
  // A thin diagonal triangle: most of its box is far from it.
  const Vec2 diagonal[3] = {{100.2f, 100.3f}, {180.7f, 180.1f}, {181.4f, 180.2f}};
  const CellRejection outside(diagonal);
  size_t kept = 0;
  for (int y = 100; y <= 181; ++y)
    for (int x = 100; x <= 182; ++x) kept += outside.rejects(x, y) ? 0 : 1;
  EXPECT_LT(kept, size_t(82 * 83 / 10));
}

TEST(AtlasLayout, RectanglesAreDisjointAndScaleWithArea) {
  Scene scene;
  const uint32_t m = testing::add_material(scene, {0.5f, 0.5f, 0.5f});
  // Three instances of different sizes (each add_quad after a name change starts a new instance).
  for (int i = 0; i < 3; ++i) {
    const float s = float(1 << i);
    testing::add_quad(scene, {0, float(i) * 10, 0}, {s, 0, 0}, {0, 0, s}, m);
    scene.instances.back().name = "quad" + std::to_string(i);
  }
  ASSERT_EQ(scene.instances.size(), 3u);
  AtlasSettings settings;
  settings.texel_density = 16;
  Diagnostics diagnostics;
  const AtlasLayout layout = layout_lightmap_atlas(scene, settings, "test", diagnostics);
  ASSERT_EQ(layout.rects.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(layout.rects[i].width, 16 << i);
    EXPECT_EQ(layout.rects[i].height, 16 << i);
    for (size_t j = i + 1; j < 3; ++j) {
      const InstanceRect &a = layout.rects[i], &b = layout.rects[j];
      const bool disjoint = a.page != b.page || a.x + a.width + 2 * settings.padding <= b.x ||
                            b.x + b.width + 2 * settings.padding <= a.x ||
                            a.y + a.height + 2 * settings.padding <= b.y || b.y + b.height + 2 * settings.padding <= a.y;
      EXPECT_TRUE(disjoint) << i << " overlaps " << j;
    }
  }
  const TexelGBuffer gbuffer = rasterize_texel_gbuffer(scene, layout, "test", diagnostics);
  EXPECT_EQ(gbuffer.texels.size(), size_t(16 * 16 + 32 * 32 + 64 * 64));
  EXPECT_TRUE(diagnostics.warnings.empty());
  for (const LiveTexel& t : gbuffer.texels) {
    EXPECT_NEAR(t.world_texel_size, 1.0f / 16.0f, 1e-4f);
    EXPECT_NEAR(length(t.geometric_normal), 1.0f, 1e-5f);
  }
}

TEST(AtlasLayout, OverlappingChartsAreReported) {
  Scene scene;
  const uint32_t m = testing::add_material(scene, {0.5f, 0.5f, 0.5f});
  testing::add_quad(scene, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}, m);
  testing::add_quad(scene, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}, m);  // same instance, same UVs
  AtlasSettings settings;
  settings.texel_density = 8;
  Diagnostics diagnostics;
  const AtlasLayout layout = layout_lightmap_atlas(scene, settings, "test", diagnostics);
  rasterize_texel_gbuffer(scene, layout, "test", diagnostics);
  ASSERT_EQ(diagnostics.warnings.size(), 1u);
  EXPECT_NE(diagnostics.warnings[0].find("overlap"), std::string::npos);
}

TEST(Dilation, FillsGutterFromNeighbours) {
  std::vector<float> coverage = {0, 0, 0, 0, 1, 0, 0, 0, 0};
  std::vector<float> value = {0, 0, 0, 0, 5, 0, 0, 0, 0};
  dilate_into_gutter(3, 3, coverage, {value.data()}, 2);
  for (float v : value) EXPECT_EQ(v, 5.0f);
}

// The ring-by-ring fill computed plainly on one thread, the reference the parallel dilate_into must
// match bit for bit: per pass, every fillable unfilled texel's filled 8-neighbours (row by row, the
// order the sums run in) averaged in double against the state before the pass.
void serial_dilate(int width, int height, std::vector<uint8_t> filled, const std::vector<uint8_t>& fillable,
                   const std::vector<float*>& channels, int passes) {
  static const int offsets[8][2] = {{-1, -1}, {0, -1}, {1, -1}, {-1, 0}, {1, 0}, {-1, 1}, {0, 1}, {1, 1}};
  for (int pass = 0; passes < 0 || pass < passes; ++pass) {
    std::vector<uint8_t> before = filled;
    std::vector<std::vector<float>> old(channels.size());
    for (size_t c = 0; c < channels.size(); ++c) old[c].assign(channels[c], channels[c] + size_t(width) * size_t(height));
    bool changed = false;
    for (size_t i = 0; i < before.size(); ++i) {
      if (before[i] || !fillable[i]) continue;
      const int x = int(i % size_t(width)), y = int(i / size_t(width));
      std::vector<size_t> from;
      for (const auto& o : offsets)
        if (x + o[0] >= 0 && x + o[0] < width && y + o[1] >= 0 && y + o[1] < height &&
            before[size_t(y + o[1]) * size_t(width) + size_t(x + o[0])])
          from.push_back(size_t(y + o[1]) * size_t(width) + size_t(x + o[0]));
      if (from.empty()) continue;
      for (size_t c = 0; c < channels.size(); ++c) {
        double total = 0;
        for (size_t j : from) total += old[c][j];
        channels[c][i] = float(total / double(from.size()));
      }
      filled[i] = 1, changed = true;
    }
    if (!changed) break;
  }
}

TEST(Dilation, ParallelRowsMatchTheSerialFill) {
  // Big enough for several row chunks; scattered covered texels and a fillable mask with holes, so
  // rings meet across chunk borders; 4 passes and "until nothing changes" (-1).
  const int width = 700, height = 1100;
  const size_t n = size_t(width) * size_t(height);
  Pcg32 rng = pcg_init(7, 0, 0);
  std::vector<uint8_t> filled(n), fillable(n);
  std::vector<float> a(n), b(n);
  for (size_t i = 0; i < n; ++i) {
    filled[i] = pcg_uniform(rng) < 0.05f;
    fillable[i] = pcg_uniform(rng) < 0.9f;
    a[i] = filled[i] ? pcg_uniform(rng) * 100.0f : 0.0f;
    b[i] = filled[i] ? pcg_uniform(rng) : 0.0f;
  }
  for (int passes : {4, -1}) {
    std::vector<float> a_serial = a, b_serial = b, a_parallel = a, b_parallel = b;
    serial_dilate(width, height, filled, fillable, {a_serial.data(), b_serial.data()}, passes);
    dilate_into(width, height, filled, fillable, {a_parallel.data(), b_parallel.data()}, passes);
    EXPECT_EQ(std::memcmp(a_serial.data(), a_parallel.data(), n * sizeof(float)), 0) << passes;
    EXPECT_EQ(std::memcmp(b_serial.data(), b_parallel.data(), n * sizeof(float)), 0) << passes;
    EXPECT_NE(std::memcmp(a.data(), a_parallel.data(), n * sizeof(float)), 0);  // it did fill something
  }
}

// The gutter fill (every cell fillable) on pages whose widths sit on and beside the 64-cell words the
// ring search works in, with sparse charts (rectangles and lone texels at the page's edges), so rings
// cross word borders, page borders and meet each other.
TEST(Dilation, GutterFillMatchesTheSerialFillAcrossWordBorders) {
  Pcg32 rng = pcg_init(11, 0, 0);
  for (int width : {1, 63, 64, 65, 127, 130}) {
    const int height = 37;
    const size_t n = size_t(width) * size_t(height);
    std::vector<float> coverage(n, 0.0f), value(n, 0.0f);
    auto cover = [&](int x, int y) {
      const size_t i = size_t(y) * size_t(width) + size_t(x);
      coverage[i] = 0.25f + pcg_uniform(rng);
      value[i] = pcg_uniform(rng) * 10.0f;
    };
    cover(0, 0), cover(width - 1, height - 1), cover(width - 1, 0);
    for (int r = 0; r < 3; ++r) {
      const int x0 = int(pcg_uniform(rng) * float(width)), y0 = int(pcg_uniform(rng) * float(height));
      for (int y = y0; y < std::min(height, y0 + 4); ++y)
        for (int x = x0; x < std::min(width, x0 + 9); ++x) cover(x, y);
    }
    std::vector<uint8_t> filled(n), fillable(n, 1);
    for (size_t i = 0; i < n; ++i) filled[i] = coverage[i] > 0;
    for (int passes : {2, 5, -1}) {
      std::vector<float> serial = value, fast = value;
      serial_dilate(width, height, filled, fillable, {serial.data()}, passes);
      dilate_into_gutter(width, height, coverage, {fast.data()}, passes);
      EXPECT_EQ(std::memcmp(serial.data(), fast.data(), n * sizeof(float)), 0) << width << " " << passes;
    }
  }
}

TEST(Sampling, CosineHemisphereIsNormalisedAndUpward) {
  Pcg32 rng = pcg_init(1, 2, 3);
  double mean_cos = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const float u1 = pcg_uniform(rng), u2 = pcg_uniform(rng);
    const Vec3 d = sample_cosine_hemisphere(u1, u2);
    ASSERT_GE(d.z, 0.0f);
    ASSERT_NEAR(length(d), 1.0f, 1e-5f);
    mean_cos += d.z;
  }
  // E[cos] under pdf cos/pi is 2/3.
  EXPECT_NEAR(mean_cos / n, 2.0 / 3.0, 4.0 * 0.2357 / std::sqrt(double(n)));
}

TEST(Sampling, EnvironmentPdfMatchesItsSamples) {
  Texture sky;
  sky.width = 16;
  sky.height = 8;
  sky.rgb.resize(16 * 8 * 3);
  for (size_t i = 0; i < sky.rgb.size(); ++i) sky.rgb[i] = float((i * 7919) % 13) + 0.1f;
  EnvironmentSampler sampler(sky);
  // Integral of pdf over the sphere = 1 (midpoint rule in (u,v) with the sin(theta) Jacobian).
  double integral = 0;
  const int nu = 256, nv = 128;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const Vec2 uv{(float(i) + 0.5f) / nu, (float(j) + 0.5f) / nv};
      const double sin_theta = std::sin(kPi * uv.y);
      integral += sampler.pdf(equirect_to_direction(uv)) * sin_theta * (2 * kPi / nu) * (kPi / nv);
    }
  EXPECT_NEAR(integral, 1.0, 2e-3);
  // Sampled directions report the pdf that pdf() gives them.
  Pcg32 rng = pcg_init(9, 9, 9);
  for (int i = 0; i < 1000; ++i) {
    float pdf = 0;
    const float u1 = pcg_uniform(rng), u2 = pcg_uniform(rng);
    const Vec3 d = sampler.sample(u1, u2, pdf);
    ASSERT_NEAR(pdf, sampler.pdf(d), 1e-3f * pdf);
  }
}

TEST(Sampling, DistributionSkipsZeroWeightCells) {
  Distribution1D d({0.0, 1.0, 0.0, 3.0, 0.0});
  for (float u : {0.0f, 0.1f, 0.25f, 0.26f, 0.9f, 0.9999f}) {
    const size_t i = d.sample(u);
    EXPECT_TRUE(i == 1 || i == 3) << u;
  }
  EXPECT_FLOAT_EQ(d.pmf(3), 0.75f);
}

TEST(RayOffset, LeavesTheSurfaceFarFromTheOrigin) {
  for (float scale : {0.0f, 1e-3f, 1.0f, 1e5f}) {
    const Vec3 p{scale, -scale, 0.5f * scale};
    const Vec3 n = normalize(Vec3{0.2f, 1.0f, -0.3f});
    const Vec3 q = offset_ray_origin(p, n, 4.0f);
    EXPECT_GT(dot(q - p, n), 0.0f) << scale;
    // Small against the geometry: a few ulps of |p| (at most ~1e-5 relative) plus 1e-6 of the scene.
    EXPECT_LT(length(q - p), 2e-6f * std::max(scale, 1.0f) * 4.0f + 1e-5f * scale) << scale;
  }
}

}  // namespace
}  // namespace exitance
