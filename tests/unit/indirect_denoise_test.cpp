// The texture-space filter of the indirect light (bundle/indirect_denoise.h, bake --denoise) on
// hand-made G-buffers whose surfaces and values are known: it keeps the direct light and a constant
// indirect light exactly, never mixes surfaces that are atlas neighbours but not neighbours in the
// world (a crease, a step, another chart), and divides the noise of a flat wall as its weights say.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "exitance/common/texture_space_filter.h"
#include "exitance/runtime/bundle/indirect_denoise.h"

namespace exitance {
namespace {

constexpr int kSide = 16;
constexpr float kTexel = 0.1f;  // world size of a texel

// A kSide x kSide page of live texels; `surface(x, y, position, normal)` places each.
template <class Surface>
TexelGBuffer page_of(Surface surface) {
  TexelGBuffer g;
  AtlasPage page;
  page.width = page.height = kSide;
  page.coverage.assign(size_t(kSide * kSide), 1.0f);
  g.pages.push_back(page);
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x) {
      LiveTexel t;
      t.page = 0, t.x = uint32_t(x), t.y = uint32_t(y);
      surface(x, y, t.position, t.geometric_normal);
      t.shading_normal = t.geometric_normal;
      t.world_texel_size = kTexel;
      g.texels.push_back(t);
    }
  return g;
}

void flat(int x, int y, Vec3& p, Vec3& n) { p = Vec3{x * kTexel, y * kTexel, 0}, n = Vec3{0, 0, 1}; }

// Per texel `samples` samples whose direct part is `direct(i)` each and whose indirect part is
// `indirect(i, s)`; recorded bounce layer 0 the direct sums, layer 1 the indirect sums.
template <class Direct, class Indirect>
LightmapEstimate estimate_of(size_t texels, uint32_t samples, Direct direct, Indirect indirect) {
  LightmapEstimate e;
  e.texels.resize(texels);
  e.recorded_bounces = 2;
  e.bounces.assign(2 * texels * 3, 0.0);
  for (size_t i = 0; i < texels; ++i)
    for (uint32_t s = 0; s < samples; ++s) {
      const double d = direct(i), v = indirect(i, s);
      TexelAccumulator& t = e.texels[i];
      for (int c = 0; c < 3; ++c) {
        t.total[c] += d + v, t.total_squared[c] += (d + v) * (d + v), t.direct[c] += d;
        e.bounces[i * 3 + size_t(c)] += d;
        e.bounces[(texels + i) * 3 + size_t(c)] += v;
      }
      ++t.samples;
    }
  return e;
}

// A deterministic noise in [-0.5, 0.5) per (texel, sample).
double noise(size_t i, uint32_t s) {
  uint32_t h = uint32_t(i) * 747796405u + s * 2891336453u + 12345u;
  h ^= h >> 16, h *= 0x7feb352du, h ^= h >> 15, h *= 0x846ca68bu, h ^= h >> 16;
  return double(h) / 4294967296.0 - 0.5;
}

TEST(IndirectDenoise, KeepsTheDirectLightAndAConstantIndirectLight) {
  const TexelGBuffer g = page_of(flat);
  const size_t n = g.texels.size();
  // Direct light varying sharply (a shadow edge every other column), indirect 0.25 everywhere.
  const LightmapEstimate e = estimate_of(n, 8, [](size_t i) { return (i % 2) ? 1.0 : 0.0; }, [](size_t, uint32_t) { return 0.25; });
  IndirectDenoiseReport report;
  const LightmapEstimate f = denoise_indirect(e, g, IndirectDenoiseSettings{.radius = 3}, &report);
  EXPECT_EQ(report.texels, n);
  EXPECT_GT(report.mean_neighbours, 30.0);  // interior windows hold all 49 texels, corners 16
  for (size_t i = 0; i < n; ++i) {
    EXPECT_EQ(f.texels[i].samples, 8u);
    EXPECT_NEAR(f.mean_total(i)[0], (i % 2 ? 1.0 : 0.0) + 0.25, 1e-6) << i;
    EXPECT_EQ(f.bounces[i * 3], e.bounces[i * 3]) << "the direct layer is kept";
    EXPECT_NEAR(f.mean_bounce(1, i)[2], 0.25, 1e-6) << i;
  }
}

TEST(IndirectDenoise, NeverMixesSurfacesThatAreNotNeighboursInTheWorld) {
  // Left half of the page: a floor. Right half, by case: a wall at a right angle (a crease), a slope
  // of 20 degrees rising from the floor's edge (a fold: only the normals tell it apart), the floor
  // raised by 0.2 m (a step: only the plane distance tells it), or a chart of another floor 10 m away
  // (a chart border: only the world distance tells it).
  const int half = kSide / 2;
  auto crease = [&](int x, int y, Vec3& p, Vec3& n) {
    if (x < half) p = Vec3{x * kTexel, 0, y * kTexel}, n = Vec3{0, 1, 0};
    else p = Vec3{half * kTexel, (x - half + 0.5f) * kTexel, y * kTexel}, n = Vec3{-1, 0, 0};
  };
  auto fold = [&](int x, int y, Vec3& p, Vec3& n) {
    const float slope = std::tan(20.0f * 3.14159265f / 180.0f), along = (x - half + 0.5f) * kTexel;
    if (x < half) p = Vec3{x * kTexel, 0, y * kTexel}, n = Vec3{0, 1, 0};
    else p = Vec3{half * kTexel + along, along * slope, y * kTexel}, n = normalize(Vec3{-slope, 1, 0});
  };
  auto step = [&](int x, int y, Vec3& p, Vec3& n) {
    p = Vec3{x * kTexel, x < half ? 0.0f : 0.2f, y * kTexel}, n = Vec3{0, 1, 0};
  };
  auto far = [&](int x, int y, Vec3& p, Vec3& n) {
    p = Vec3{x * kTexel + (x < half ? 0.0f : 10.0f), 0, y * kTexel}, n = Vec3{0, 1, 0};
  };
  const TexelGBuffer cases[] = {page_of(crease), page_of(fold), page_of(step), page_of(far)};
  for (const TexelGBuffer& g : cases) {
    const size_t n = g.texels.size();
    const LightmapEstimate e =
        estimate_of(n, 4, [](size_t) { return 0.0; }, [&](size_t i, uint32_t) { return g.texels[i].x < uint32_t(half) ? 1.0 : 0.2; });
    const LightmapEstimate f = denoise_indirect(e, g, IndirectDenoiseSettings{.radius = 3});
    for (size_t i = 0; i < n; ++i) EXPECT_NEAR(f.mean_total(i)[1], g.texels[i].x < uint32_t(half) ? 1.0 : 0.2, 1e-6) << i;
  }
}

TEST(IndirectDenoise, DividesTheNoiseOfAFlatWallAsItsWeightsSay) {
  const TexelGBuffer g = page_of(flat);
  const size_t n = g.texels.size();
  const uint32_t samples = 4;
  const LightmapEstimate e = estimate_of(n, samples, [](size_t) { return 0.5; }, [](size_t i, uint32_t s) { return 0.25 + noise(i, s); });
  const int radius = 3;
  const LightmapEstimate f = denoise_indirect(e, g, IndirectDenoiseSettings{.radius = radius});
  // Interior texels (whole windows): the spread of the means about 0.75 shrinks by the window's
  // effective count (sum w)^2 / sum w^2, and each texel's variance of the mean is sum w^2 V / (sum w)^2.
  double weight = 0, weight_squared = 0;
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx) {
      const double w = texture_space_filter_weight(Vec3{0, 0, 0}, Vec3{0, 0, 1}, kTexel, Vec3{dx * kTexel, dy * kTexel, 0},
                                                   Vec3{0, 0, 1}, dx, dy, radius);
      weight += w, weight_squared += w * w;
    }
  const double effective = weight * weight / weight_squared;
  EXPECT_GT(effective, 20.0);
  double before = 0, after = 0, effective_here = 0;
  size_t interior = 0;
  for (size_t i = 0; i < n; ++i) {
    const LiveTexel& t = g.texels[i];
    if (int(t.x) < radius || int(t.y) < radius || int(t.x) >= kSide - radius || int(t.y) >= kSide - radius) continue;
    ++interior;
    before += std::pow(e.mean_total(i)[0] - 0.75, 2), after += std::pow(f.mean_total(i)[0] - 0.75, 2);
    // Its weights: the window's times the range weight of the two texels' indirect means (grey:
    // the three channels equal).
    double expected_variance = 0, weights = 0, weights_squared = 0;
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx) {
        const size_t j = size_t((int(t.y) + dy) * kSide + int(t.x) + dx);
        const float difference = float(e.mean_total(j)[0] - e.mean_direct(j)[0]) - float(e.mean_total(i)[0] - e.mean_direct(i)[0]);
        const double w = texture_space_filter_weight(t.position, t.geometric_normal, kTexel, g.texels[j].position,
                                                     g.texels[j].geometric_normal, dx, dy, radius) *
                         texture_space_filter_range_weight(3 * difference * difference,
                                                           3 * (e.variance_of_mean(i)[0] + e.variance_of_mean(j)[0]));
        expected_variance += w * w * e.variance_of_mean(j)[0];
        weights += w, weights_squared += w * w;
      }
    effective_here += weights * weights / weights_squared;
    EXPECT_NEAR(f.variance_of_mean(i)[0], expected_variance / (weights * weights), 1e-4 * expected_variance / (weights * weights));
  }
  ASSERT_GT(interior, 50u);
  // The noise is independent per texel: the mean squared deviation falls by about the effective
  // count of the weights used, (sum w)^2 / sum w^2 (the range weight keeps back neighbours far off
  // by chance, so fewer than the window's `effective`; a factor 2 of slack for 100 texels' sampling).
  const double effective_used = effective_here / double(interior);
  EXPECT_GT(effective_used, 0.4 * effective);
  EXPECT_LT(after, before / effective_used * 2.0) << "before " << before / interior << " after " << after / interior;
  EXPECT_GT(after, before / effective_used / 2.0);
}

TEST(IndirectDenoise, LeaksNoLightUnderAnOccluderOnTheSurface) {
  // A floor lit by noisy indirect light, with a 4 x 4 patch under a box resting on it: black in
  // every sample (no variance). Geometry cannot tell the patch apart; the values can.
  const TexelGBuffer g = page_of(flat);
  auto under_box = [&](size_t i) { return g.texels[i].x >= 6 && g.texels[i].x < 10 && g.texels[i].y >= 6 && g.texels[i].y < 10; };
  const LightmapEstimate e = estimate_of(g.texels.size(), 8, [&](size_t i) { return under_box(i) ? 0.0 : 0.5; },
                                         [&](size_t i, uint32_t s) { return under_box(i) ? 0.0 : 0.25 + 0.2 * noise(i, s); });
  const LightmapEstimate f = denoise_indirect(e, g, IndirectDenoiseSettings{.radius = 3});
  double lit = 0;
  size_t lit_texels = 0;
  for (size_t i = 0; i < g.texels.size(); ++i) {
    if (under_box(i)) {
      EXPECT_LT(f.mean_total(i)[0], 1e-4f) << i;  // against 0.25 lit beside it
    } else {
      lit += f.mean_total(i)[0] - 0.5, ++lit_texels;
    }
  }
  EXPECT_NEAR(lit / double(lit_texels), 0.25, 0.01) << "the lit floor is not darkened by the patch";
}

TEST(IndirectDenoise, RefusesEstimatesItCannotSplit) {
  const TexelGBuffer g = page_of(flat);
  LightmapEstimate e = estimate_of(g.texels.size(), 2, [](size_t) { return 0.0; }, [](size_t, uint32_t) { return 1.0; });
  LightmapEstimate layered = e;
  layered.light_layers = 1;
  layered.light_sums.assign(g.texels.size() * 3, 0.0);
  EXPECT_THROW(denoise_indirect(layered, g, {}), std::invalid_argument);
  LightmapEstimate directional = e;
  directional.sh1.assign(g.texels.size() * 9, 0.0);
  EXPECT_THROW(denoise_indirect(directional, g, {}), std::invalid_argument);
  LightmapEstimate fewer = e;
  fewer.texels.pop_back();
  EXPECT_THROW(denoise_indirect(fewer, g, {}), std::invalid_argument);
  EXPECT_THROW(denoise_indirect(e, g, IndirectDenoiseSettings{.radius = 0}), std::invalid_argument);
}

}  // namespace
}  // namespace exitance
