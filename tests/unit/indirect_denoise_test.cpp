// The texture-space filter of the indirect light (bundle/indirect_denoise.h, bake --denoise) on
// hand-made G-buffers whose surfaces and values are known: it keeps the direct light and a constant
// indirect light exactly, and a linearly changing one, never mixes surfaces that are atlas
// neighbours but not neighbours in the world (a crease, a step, another chart), and divides the
// noise of a flat wall as its weights say.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <vector>

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
  // 16 samples: with 4, each texel's variance is estimated from 3 degrees of freedom, and the range
  // weight (whose variance the neighbour's enters capped at kFilterNeighbourVariance times the
  // texel's) follows that noise: the spread then fell 2.6x less than the weights' count says.
  const uint32_t samples = 16;
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
  size_t interior = 0, fits = 0;
  for (size_t i = 0; i < n; ++i) {
    const LiveTexel& t = g.texels[i];
    if (int(t.x) < radius || int(t.y) < radius || int(t.x) >= kSide - radius || int(t.y) >= kSide - radius) continue;
    ++interior;
    before += std::pow(e.mean_total(i)[0] - 0.75, 2), after += std::pow(f.mean_total(i)[0] - 0.75, 2);
    // Its weights: the window's times the range weight of the two texels' indirect means (grey: the
    // three channels equal), times the linear fit's row (texture_space_filter.h).
    struct Neighbour {
      size_t j;
      double w, u, v;
    };
    std::vector<Neighbour> window;
    double m00 = 0, m01 = 0, m02 = 0, m11 = 0, m12 = 0, m22 = 0;
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx) {
        const size_t j = size_t((int(t.y) + dy) * kSide + int(t.x) + dx);
        const float difference = float(e.mean_total(j)[0] - e.mean_direct(j)[0]) - float(e.mean_total(i)[0] - e.mean_direct(i)[0]);
        const double w = texture_space_filter_weight(t.position, t.geometric_normal, kTexel, g.texels[j].position,
                                                     g.texels[j].geometric_normal, dx, dy, radius) *
                         texture_space_filter_range_weight(
                             3 * difference * difference,
                             3 * texture_space_filter_range_variance(e.variance_of_mean(i)[0], e.variance_of_mean(j)[0]));
        if (w <= 0) continue;
        const Vec2 offset = texture_space_filter_plane_offset(t.geometric_normal, g.texels[j].position - t.position, kTexel);
        window.push_back({j, w, offset.x, offset.y});
        m00 += w, m01 += w * offset.x, m02 += w * offset.y;
        m11 += w * offset.x * offset.x, m12 += w * offset.x * offset.y, m22 += w * offset.y * offset.y;
      }
    double c0 = 0, c1 = 0, c2 = 0;
    ASSERT_TRUE(texture_space_filter_linear_row(m00, m01, m02, m11, m12, m22, c0, c1, c2)) << "a whole window spans the plane";
    // The texel takes the weighted mean or the fit (texture_space_filter_prefers_fit): its variance
    // is sum w^2 V / (sum w)^2 for the weights of one of them.
    double mean_variance = 0, mean_weights = 0, mean_squared = 0, fit_variance = 0, fit_weights = 0, fit_squared = 0;
    for (const Neighbour& q : window) {
      const double l = q.w * (c0 + c1 * q.u + c2 * q.v);
      mean_variance += q.w * q.w * e.variance_of_mean(q.j)[0], mean_weights += q.w, mean_squared += q.w * q.w;
      fit_variance += l * l * e.variance_of_mean(q.j)[0], fit_weights += l, fit_squared += l * l;
    }
    EXPECT_NEAR(fit_weights, 1.0, 1e-9) << "the fit's weights sum to 1";
    mean_variance /= mean_weights * mean_weights;
    const double reported = f.variance_of_mean(i)[0];
    const bool took_fit = std::abs(reported - fit_variance) < std::abs(reported - mean_variance);
    const double expected_variance = took_fit ? fit_variance : mean_variance;
    fits += took_fit ? 1 : 0;
    effective_here += took_fit ? 1.0 / fit_squared : mean_weights * mean_weights / mean_squared;
    EXPECT_NEAR(reported, expected_variance, 1e-4 * expected_variance);
  }
  // (In a whole window the two nearly agree: the window's offsets are balanced, so the fit's
  // variance is the mean's within a few parts in a thousand and either may be taken.)
  std::printf("[denoise] %zu of %zu interior texels of a flat wall took the fit\n", fits, interior);
  ASSERT_GT(interior, 50u);
  // The noise is independent per texel: the mean squared deviation falls by about the effective
  // count of the weights used, (sum w)^2 / sum w^2 (the range weight keeps back neighbours far off
  // by chance, and a fit of three parameters spends some, so fewer than the window's mean's
  // `effective`; a factor 2 of slack for 100 texels' sampling).
  const double effective_used = effective_here / double(interior);
  EXPECT_GT(effective_used, 0.3 * effective);
  EXPECT_LT(after, before / effective_used * 2.0) << "before " << before / interior << " after " << after / interior;
  EXPECT_GT(after, before / effective_used / 2.0);
}

// Indirect light that changes linearly across a wall (each texel's mean exactly 0.2 + 0.05 x +
// 0.02 y, its eight samples that +- 0.2, so the range weight takes nearly every neighbour): a
// weighted mean is pulled toward the inside at the border and corner texels, whose windows lie to
// one side (by ~0.08 in a corner, 3.5 of its standard errors); the fit is not. No texel's error may
// pass twice the standard error it reports, and the far corner's none at all.
TEST(IndirectDenoise, KeepsALinearIndirectLightAtTheBordersWithinItsNoise) {
  const TexelGBuffer g = page_of(flat);
  const size_t n = g.texels.size();
  auto linear = [&](size_t i) { return 0.2 + 0.05 * g.texels[i].x + 0.02 * g.texels[i].y; };
  const LightmapEstimate e = estimate_of(n, 8, [](size_t) { return 0.5; },
                                         [&](size_t i, uint32_t s) { return linear(i) + (s % 2 == 0 ? 0.2 : -0.2); });
  const LightmapEstimate f = denoise_indirect(e, g, IndirectDenoiseSettings{.radius = 3});
  for (size_t i = 0; i < n; ++i) {
    const double error = f.mean_total(i)[0] - (0.5 + linear(i)), standard_error = std::sqrt(f.variance_of_mean(i)[0]);
    EXPECT_LE(std::abs(error), 2.0 * standard_error) << "texel " << g.texels[i].x << ", " << g.texels[i].y;
    EXPECT_NEAR(f.mean_bounce(1, i)[1] - linear(i), error, 1e-6) << "the layer takes the same weights";
  }
  EXPECT_NEAR(f.mean_total(n - 1)[0], 0.5 + linear(n - 1), 1e-6) << "the corner at the light's steepest side takes the fit";
}

// One texel lit by a rare path (its four samples 0, 0, 0 and 200: a mean of 50 and a variance of the
// mean of 2 500) among texels of indirect light 0.25 +- 0.1: its neighbours' own noise does not
// explain it, so it stays out of their windows (texture_space_filter_range_variance caps its
// variance's part at kFilterNeighbourVariance times theirs); counted as V_i + V_j it was taken in
// and spread over the window (0.25 -> 0.31 beside it).
TEST(IndirectDenoise, KeepsARarePathsTexelOutOfItsNeighbours) {
  const TexelGBuffer g = page_of(flat);
  const size_t n = g.texels.size(), spike = size_t(8 * kSide + 8);
  const LightmapEstimate e = estimate_of(n, 4, [](size_t) { return 0.0; }, [&](size_t i, uint32_t s) {
    if (i == spike) return s == 3 ? 200.0 : 0.0;
    return 0.25 + (s % 2 == 0 ? 0.1 : -0.1);
  });
  const LightmapEstimate f = denoise_indirect(e, g, IndirectDenoiseSettings{.radius = 3});
  for (size_t i = 0; i < n; ++i) {
    if (i == spike) continue;
    EXPECT_NEAR(f.mean_total(i)[0], 0.25, 1e-3) << "texel " << g.texels[i].x << ", " << g.texels[i].y;
  }
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
