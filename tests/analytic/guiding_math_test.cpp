// The guiding math shared by C++ and GLSL (runtime/common: concentric_hemisphere.h,
// guided_direction.h, path.h's mixture): the map preserves projected solid angle and is invertible, the guided and
// mixture pdfs integrate to 1, sampled directions follow the pdf (chi-square), CDF inversion is exact
// at bin edges, and degenerate inputs give no NaN.
//
// Chi-square thresholds: Wilson-Hilferty quantile at p = 1e-4 for the test's degrees of freedom; the
// seeds are fixed, so a pass is reproducible and a wrong pdf (even by a few % in a few bins) fails.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "exitance/runtime/core/scene_access.h"
#include "exitance/common/emitter_guide_fold.h"
#include "exitance/common/guide_fold.h"  // after scene_access.h, as the cache includes it
#include "exitance/runtime/core/emitter_guiding_cache.h"
#include "exitance/runtime/core/grid_guiding_cache.h"

namespace exitance {
namespace {

// Upper p-quantile of chi-square with k degrees of freedom (Wilson-Hilferty), z = normal quantile.
double chi_square_quantile(double k, double z) {
  const double a = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - a + z * std::sqrt(a), 3.0);
}
constexpr double kZ1e4 = 3.719;  // one-sided normal quantile at p = 1e-4

// A CDF over the bins from weights: some bins 0, a few large, the rest random.
std::vector<float> make_cdf(uint64_t seed, bool with_zeros) {
  Pcg32 rng = pcg_init(seed, 7, 0);
  std::vector<double> w(kGuideBins);
  for (uint b = 0; b < kGuideBins; ++b) {
    const float u = pcg_uniform(rng);
    w[b] = u * u * u;
    if (with_zeros && b % 7 == 3) w[b] = 0;
    if (b % 41 == 5) w[b] = 20;
  }
  std::vector<float> cdf(kGuideBins + 1, 0.0f);
  double total = 0;
  for (double x : w) total += x;
  double run = 0;
  for (uint b = 0; b < kGuideBins; ++b) {
    run += w[b];
    cdf[b + 1] = float(run / total);
  }
  cdf[kGuideBins] = 1.0f;
  return cdf;
}

GuideVertex guided(const std::vector<float>& cdf, uint normal_class, float m) {
  GuideVertex g;
  g.guided_probability = m;
  g.normal_class = normal_class;
  g.cdf = cdf.data();
  g.uniform_probability = 0;
  return g;
}

TEST(ConcentricHemisphere, RoundTripsAndGivesUnitDirections) {
  for (int i = 0; i <= 64; ++i)
    for (int j = 0; j <= 64; ++j) {
      const float s = std::min(i / 64.0f, 0.99999994f), t = std::min(j / 64.0f, 0.99999994f);
      const Vec3 d = concentric_square_to_hemisphere(s, t);
      EXPECT_NEAR(length(d), 1.0f, 2e-6f);
      EXPECT_GE(d.z, 0.0f);
      const Vec2 back = hemisphere_to_concentric_square(d);
      // At the pole (s, t) = (0.5, 0.5) every square point maps to z = 1: no inverse to compare.
      if (std::fabs(s - 0.5f) + std::fabs(t - 0.5f) < 1e-6f) continue;
      EXPECT_NEAR(back.x, s, 2e-5f) << s << "," << t;
      EXPECT_NEAR(back.y, t, 2e-5f) << s << "," << t;
    }
}

// A point drawn inside a bin, even a thousandth of a bin from its edge, maps back to that bin: the
// sampler (forward map) and the pdf (inverse map) agree on every bin's extent.
TEST(ConcentricHemisphere, PointsInsideABinMapBackToIt) {
  for (uint b = 0; b < kGuideBins; ++b)
    for (float fx : {0.001f, 0.5f, 0.999f})
      for (float fy : {0.001f, 0.5f, 0.999f}) ASSERT_EQ(guide_bin_of_local(guide_bin_point(b, fx, fy)), b) << fx << "," << fy;
}

// Cosine-distributed directions, drawn independently of the map (uniform directions accepted with
// probability cos), must fall into the 256 bins equally often: every bin has the same cosine mass.
TEST(ConcentricHemisphere, BinsHaveEqualCosineMass) {
  const int n = kGuideBins * 400;
  std::vector<double> count(kGuideBins, 0);
  Pcg32 rng = pcg_init(3, 1, 0);
  for (int k = 0; k < n; ++k) {
    const float u1 = pcg_uniform(rng), u2 = pcg_uniform(rng);
    Vec3 d = uniform_sphere(u1, u2);
    d.z = std::fabs(d.z);
    if (pcg_uniform(rng) >= d.z) {
      --k;
      continue;
    }
    count[guide_bin_of_local(d)] += 1;
  }
  const double expected = double(n) / kGuideBins;
  double chi2 = 0;
  for (double c : count) chi2 += (c - expected) * (c - expected) / expected;
  EXPECT_LT(chi2, chi_square_quantile(kGuideBins - 1, kZ1e4));
}

TEST(GuidedDirection, NormalClassFramesAreInverseAndPointAlongTheClassNormal) {
  const Vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (uint k = 0; k < kGuideNormalClasses; ++k) {
    EXPECT_EQ(guide_normal_class(axes[k]), k);
    const Vec3 up = guide_from_class_local(k, Vec3(0, 0, 1));
    EXPECT_EQ(up.x, axes[k].x);
    EXPECT_EQ(up.y, axes[k].y);
    EXPECT_EQ(up.z, axes[k].z);
    const Vec3 w = normalize(Vec3(0.3f, -0.5f, 0.7f));
    const Vec3 back = guide_from_class_local(k, guide_to_class_local(k, w));
    EXPECT_EQ(back.x, w.x);
    EXPECT_EQ(back.y, w.y);
    EXPECT_EQ(back.z, w.z);
  }
  EXPECT_EQ(guide_normal_class(normalize(Vec3(0.2f, -0.9f, 0.3f))), 3u);
}

// Midpoint rule over (z, phi), a parameterisation independent of the bins' own map; the bins' edges
// cross the grid cells, so the rule's error is about (cells on edges) / (cells) ~ 1e-3 at 2000^2.
double integrate_over_sphere(const std::function<double(Vec3)>& f, int nz, int nphi) {
  double sum = 0;
  for (int i = 0; i < nz; ++i) {
    const double z = -1.0 + (i + 0.5) * 2.0 / nz, r = std::sqrt(std::max(0.0, 1 - z * z));
    for (int j = 0; j < nphi; ++j) {
      const double phi = (j + 0.5) * 2.0 * M_PI / nphi;
      sum += f(Vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)));
    }
  }
  return sum * (2.0 / nz) * (2.0 * M_PI / nphi);
}

TEST(GuidedDirection, GuidedAndMixturePdfsIntegrateToOne) {
  const std::vector<float> cdf = make_cdf(11, true);
  for (uint k : {0u, 3u, 4u}) {
    const GuideVertex g = guided(cdf, k, 0.5f);
    const double guided_mass = integrate_over_sphere([&](Vec3 w) { return guided_component_pdf(g, w); }, 2000, 2000);
    EXPECT_NEAR(guided_mass, 1.0, 3e-3) << "class " << k;
    // A surface tilted against its class axis: the mixture still integrates to 1 over the sphere.
    const Vec3 n = normalize(guide_from_class_local(k, Vec3(0.4f, 0.2f, 1.0f)));
    const SurfacePoint x{Vec3(0, 0, 0), n, n};
    const double mixture_mass = integrate_over_sphere([&](Vec3 w) { return continuation_pdf(g, x, w); }, 2000, 2000);
    EXPECT_NEAR(mixture_mass, 1.0, 3e-3) << "class " << k;
  }
}

// Sampled directions against the pdf on a grid 4x finer than the bins (so the point inside a bin, from
// the bin number's remainder and the second number, is tested too): expected counts from the pdf integrated over each grid cell.
TEST(GuidedDirection, SampledDirectionsFollowTheGuidedPdf) {
  const std::vector<float> cdf = make_cdf(5, true);
  const GuideVertex g = guided(cdf, 2, 1.0f);
  constexpr int kFine = 32;  // 2 x 2 cells per bin
  const int n = 400000;
  std::vector<double> count(kFine * kFine, 0);
  Pcg32 rng = pcg_init(9, 2, 0);
  for (int k = 0; k < n; ++k) {
    const float u1 = pcg_uniform(rng), u2 = pcg_uniform(rng);
    const Vec3 w = guided_component_sample(g, u1, u2);
    ASSERT_GT(guided_component_pdf(g, w), 0.0f);
    const Vec2 st = hemisphere_to_concentric_square(guide_to_class_local(g.normal_class, w));
    count[std::min(int(st.y * kFine), kFine - 1) * kFine + std::min(int(st.x * kFine), kFine - 1)] += 1;
  }
  double chi2 = 0;
  int dof = -1;
  for (int c = 0; c < kFine * kFine; ++c) {
    const uint bin = uint((c / kFine) / 2) * kGuideBinsPerSide + uint((c % kFine) / 2);
    const double expected = n * guide_bin_probability(cdf.data(), bin) / 4.0;
    if (expected == 0) {
      EXPECT_EQ(count[c], 0) << "a sample in a bin of probability 0";
      continue;
    }
    chi2 += (count[c] - expected) * (count[c] - expected) / expected;
    ++dof;
  }
  EXPECT_LT(chi2, chi_square_quantile(dof, kZ1e4));
}

// The one-sample mixture at a tilted surface, over the whole sphere (cylindrical equal-area grid):
// every direction counts, also those the sampler ends the path on (pdf 0 returned).
TEST(GuidedDirection, SampledDirectionsFollowTheMixturePdf) {
  const std::vector<float> cdf = make_cdf(13, false);
  const GuideVertex g = guided(cdf, 4, 0.5f);
  const Vec3 n = normalize(Vec3(0.3f, -0.2f, 1.0f));
  const SurfacePoint x{Vec3(0, 0, 0), n, n};
  constexpr int kZ = 24, kPhi = 48;
  const int n_samples = 300000;
  std::vector<double> count(kZ * kPhi, 0);
  auto cell_of = [&](Vec3 w) {
    const int iz = std::min(int((w.z + 1) * 0.5f * kZ), kZ - 1);
    double phi = std::atan2(w.y, w.x);
    if (phi < 0) phi += 2 * M_PI;
    return iz * kPhi + std::min(int(phi / (2 * M_PI) * kPhi), kPhi - 1);
  };
  int ended = 0;
  for (int k = 0; k < n_samples; ++k) {
    PathSampler rng = path_sampler(21, 3, uint32_t(k), kSamplerIndependent);  // independent draws: a chi-square test
    const DirectionSample d = sample_continuation(g, x, rng);
    ASSERT_TRUE(std::isfinite(d.pdf));
    if (d.pdf > 0) EXPECT_NEAR(d.pdf, continuation_pdf(g, x, d.direction), 1e-6f * d.pdf);
    else ++ended;
    count[cell_of(d.direction)] += 1;
  }
  // Expected mass per cell: 16 x 16 midpoint sub-grid of the cell in (z, phi).
  std::vector<double> mass(kZ * kPhi, 0);
  constexpr int kSub = 16;
  for (int iz = 0; iz < kZ * kSub; ++iz)
    for (int ip = 0; ip < kPhi * kSub; ++ip) {
      const double z = -1 + (iz + 0.5) * 2.0 / (kZ * kSub), r = std::sqrt(1 - z * z);
      const double phi = (ip + 0.5) * 2 * M_PI / (kPhi * kSub);
      const Vec3 w(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z));
      mass[(iz / kSub) * kPhi + ip / kSub] += continuation_pdf(g, x, w) * (2.0 / (kZ * kSub)) * (2 * M_PI / (kPhi * kSub));
    }
  double chi2 = 0;
  int dof = -1;
  for (int c = 0; c < kZ * kPhi; ++c) {
    const double expected = n_samples * mass[c];
    if (expected < 5) continue;  // sparse cells: chi-square's approximation does not hold
    chi2 += (count[c] - expected) * (count[c] - expected) / expected;
    ++dof;
  }
  EXPECT_GT(dof, 400);
  EXPECT_LT(chi2, chi_square_quantile(dof, kZ1e4));
  EXPECT_GT(ended, 0);  // the class hemisphere reaches under the tilted surface: some samples end
}

TEST(GuidedDirection, CdfInversionIsExactAtBinEdges) {
  const std::vector<float> cdf = make_cdf(17, true);
  for (uint k = 1; k < kGuideBins; ++k) {
    const float edge = cdf[k];
    if (guide_bin_probability(cdf.data(), k) > 0 && edge < 1.0f) {
      EXPECT_EQ(guide_sample_bin(cdf.data(), edge), k);
    }
    const float below = std::nextafter(edge, 0.0f);
    if (guide_bin_probability(cdf.data(), k - 1) > 0 && below >= cdf[k - 1]) {
      EXPECT_EQ(guide_sample_bin(cdf.data(), below), k - 1);
    }
  }
  EXPECT_EQ(guide_sample_bin(cdf.data(), 0.0f), guide_bin_probability(cdf.data(), 0) > 0 ? 0u : 1u);
  const uint last = guide_sample_bin(cdf.data(), 0.99999994f);
  EXPECT_GT(guide_bin_probability(cdf.data(), last), 0.0f);
}

TEST(GuidedDirection, DegenerateInputsGiveNoNaN) {
  // All the mass in one bin, the rest exactly 0.
  std::vector<float> cdf(kGuideBins + 1, 0.0f);
  for (uint b = 100; b <= kGuideBins; ++b) cdf[b] = 1.0f;  // bin 99 holds everything
  const GuideVertex g = guided(cdf, 1, 0.5f);
  for (float u : {0.0f, 0.5f, 0.99999994f}) EXPECT_EQ(guide_sample_bin(cdf.data(), u), 99u);
  for (float u : {0.0f, 0.99999994f}) {
    const Vec3 w = guided_component_sample(g, u, u);
    EXPECT_TRUE(std::isfinite(w.x) && std::isfinite(w.y) && std::isfinite(w.z));
    EXPECT_NEAR(length(w), 1.0f, 1e-5f);
  }
  const Vec3 odd[] = {{0, 0, 0}, {0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {0, -1, 0}, {1e-30f, 0, 0}, {0, 0, 1.0000001f}};
  for (Vec3 w : odd) {
    const float p = guided_component_pdf(g, w);
    EXPECT_TRUE(std::isfinite(p));
    EXPECT_GE(p, 0.0f);
    const Vec2 st = hemisphere_to_concentric_square(w);
    EXPECT_TRUE(st.x >= 0 && st.x <= 1 && st.y >= 0 && st.y <= 1);
    EXPECT_LT(guide_normal_class(w), kGuideNormalClasses);
  }
  // The pole and the square's corners.
  for (Vec2 st : {Vec2(0.5f, 0.5f), Vec2(0, 0), Vec2(0.99999994f, 0.99999994f), Vec2(0, 0.99999994f)}) {
    const Vec3 d = concentric_square_to_hemisphere(st.x, st.y);
    EXPECT_NEAR(length(d), 1.0f, 1e-5f);
    EXPECT_LT(guide_bin_of_local(d), kGuideBins);
  }
  // A cosine vertex is exactly the cosine strategy.
  const Vec3 n = normalize(Vec3(0.1f, 0.2f, 1.0f));
  const SurfacePoint x{Vec3(0, 0, 0), n, n};
  PathSampler a = path_sampler(1, 2, 3, kSamplerSobol), b = path_sampler(1, 2, 3, kSamplerSobol);
  const DirectionSample da = sample_continuation(guide_vertex_cosine(), x, a);
  const DirectionSample db = sample_continuation(kStrategyCosine, x, b);
  EXPECT_EQ(da.pdf, db.pdf);
  EXPECT_EQ(da.direction.x, db.direction.x);
  EXPECT_EQ(continuation_weight(guide_vertex_cosine(), x, da), 1.0f);
}

// common/guide_fold.h, the fold both backends run (GridGuidingCache::swap, fold_guide.comp), on
// closed forms: a bin's cumulative mean, and a record's CDF from bins shrunk toward their mean.
TEST(GuideFold, ABinKeepsTheCumulativeMeanOfItsTargets) {
  EXPECT_EQ(GridGuidingCache::kUniformFloor, kGuideUniformFloor);
  const double units = 16777216.0;
  float radiance = 0, weight = 0;
  EXPECT_FALSE(guide_fold_bin(radiance, weight, 0, 0, units));
  EXPECT_EQ(radiance, 0.0f);
  EXPECT_TRUE(guide_fold_bin(radiance, weight, uint64_t(3.0 * units * 4), 4, units));  // four targets of 3
  EXPECT_FLOAT_EQ(radiance, 3.0f);
  EXPECT_EQ(weight, 4.0f);
  EXPECT_TRUE(guide_fold_bin(radiance, weight, uint64_t(9.0 * units * 12), 12, units));  // twelve of 9
  EXPECT_FLOAT_EQ(radiance, (4 * 3.0f + 12 * 9.0f) / 16);
  EXPECT_EQ(weight, 16.0f);
}

TEST(GuideFold, TheCdfFollowsTheShrunkBinsWithAUniformFloor) {
  std::vector<float> radiance(kGuideBins, 0.0f), weight(kGuideBins, 8.0f), cdf(kGuideBins + 1, -1.0f);
  radiance[7] = 1.0f;  // one lit bin among dark ones
  const GuideFoldFront front = guide_fold_rebuild(GuideFoldRecord{radiance.data(), weight.data(), cdf.data()}, 0.5f);
  // Every bin has weight 8 = kGuidePriorSamples: shrunk to (L_b + prior) / 2, prior = 1 / 256.
  const double prior = 1.0 / kGuideBins, lit = (1.0 + prior) / 2, dark = prior / 2, total = lit + (kGuideBins - 1) * dark;
  EXPECT_FLOAT_EQ(front.expected_cosine, float(total / kGuideBins));
  EXPECT_EQ(front.guided_probability, 0.5f);
  EXPECT_EQ(cdf[0], 0.0f);
  EXPECT_EQ(cdf[kGuideBins], 1.0f);
  const double floor = kGuideUniformFloor / kGuideBins, share = 1.0 - kGuideUniformFloor;
  for (uint32_t b = 0; b < kGuideBins; ++b)
    EXPECT_NEAR(cdf[b + 1] - cdf[b], share * (b == 7 ? lit : dark) / total + floor, 1e-6) << "bin " << b;
  // Nothing learned: no guided share (the vertex samples cosine only; its CDF, the floor's steps
  // closed by a last step to 1, is never read).
  std::fill(radiance.begin(), radiance.end(), 0.0f);
  const GuideFoldFront none = guide_fold_rebuild(GuideFoldRecord{radiance.data(), weight.data(), cdf.data()}, 0.5f);
  EXPECT_EQ(none.guided_probability, 0.0f);
  EXPECT_EQ(none.expected_cosine, 0.0f);
  for (uint32_t b = 0; b < kGuideBins; ++b) EXPECT_NEAR(cdf[b], b * floor, 1e-7);
  EXPECT_EQ(cdf[kGuideBins], 1.0f);
}


// common/emitter_guide_fold.h, emitter guiding's fold on both backends (EmitterGuidingCache::swap,
// fold_emitter_guide.comp), on closed forms. Punctual lights, four of equal power, all learned light
// on the first: its CDF step is 0.9 + 0.1 / 4, the others' 0.1 / 4; the second moment under the
// default is sum q^2 / p0 = 3.43, under the 0.5 mixture sum q^2 / (q / 2 + 1 / 8) = 1.47002, a gain of
// 2.333 >= kEmitterFoldMinSecondMomentGain: guided. Two lights learned 3 : 1: gain 1.14, not guided.
TEST(EmitterGuideFold, PunctualSharesAndTheGainRule) {
  EXPECT_EQ(EmitterGuidingCache::kFloor, kEmitterFoldFloor);
  EXPECT_EQ(EmitterGuidingCache::kPseudoSamplesPerPatch, kEmitterFoldPseudoSamplesPerPatch);
  EXPECT_EQ(EmitterGuidingCache::kMinSecondMomentGain, kEmitterFoldMinSecondMomentGain);
  std::vector<double> learned = {2.0, 0.0, 0.0, 0.0};
  const std::vector<float> defaults(4, 0.25f);
  std::vector<float> cdf(5, -1.0f);
  EmitterFoldRecord r{};
  r.punctual_learned = learned.data();
  r.punctual_default = defaults.data();
  r.punctual_cdf = cdf.data();
  EXPECT_EQ(emitter_fold_rebuild_punctual(r, 4, 0.5f), 0.5f);
  EXPECT_EQ(cdf[0], 0.0f);
  EXPECT_FLOAT_EQ(cdf[1], 0.925f);
  EXPECT_NEAR(cdf[2] - cdf[1], 0.025f, 1e-7);  // a difference of floats near 0.95
  EXPECT_EQ(cdf[4], 1.0f);
  EXPECT_NEAR(emitter_fold_second_moment_gain(r, kEmitterFoldPunctual, 4, 0.5f), 3.43 / 1.4700193, 1e-5);
  learned = {3.0, 1.0};
  const std::vector<float> halves(2, 0.5f);
  r.punctual_default = halves.data();
  EXPECT_EQ(emitter_fold_rebuild_punctual(r, 2, 0.5f), 0.0f);
  EXPECT_FLOAT_EQ(cdf[1], 0.9f * 0.75f + 0.05f);
  EXPECT_NEAR(emitter_fold_second_moment_gain(r, kEmitterFoldPunctual, 2, 0.5f), 1.2025 / 1.0533243, 1e-5);
  // Nothing learned: the default's CDF, not guided.
  learned = {0.0, 0.0};
  EXPECT_EQ(emitter_fold_rebuild_punctual(r, 2, 0.5f), 0.0f);
  EXPECT_FLOAT_EQ(cdf[1], 0.5f);
}

// Patches pooled per cluster: cluster 0 = patches {0, 1} learned 1 : 0 from n = 8 samples (trust
// 8 / (8 + 4 x 2) = 1/2: the shares 1/2 x learned + 1/2 x the cluster's sum spread by default power),
// cluster 1 = patch {2} never reached (share 0). The fold adds fixed-point sums and counts.
TEST(EmitterGuideFold, PatchSharesArePooledPerClusterByTrust) {
  std::vector<double> learned(3, 0.0);
  std::vector<uint32_t> samples(3, 0);
  const double units = 1024.0;
  emitter_fold_add(learned[0], uint64_t(2.0 * units), units);
  samples[0] += 8;
  EXPECT_EQ(learned[0], 2.0);
  const std::vector<float> defaults = {0.25f, 0.25f, 0.5f};
  const std::vector<uint32_t> clusters = {0, 2, 3};
  std::vector<float> cdf(4, -1.0f);
  EmitterFoldRecord r{};
  r.learned = learned.data();
  r.samples = samples.data();
  r.default_probability = defaults.data();
  r.cluster_first = clusters.data();
  r.cdf = cdf.data();
  const float guided = emitter_fold_rebuild_patches(r, 3, 2, 0.5f);
  const double share0 = 0.5 * 1.0 + 0.5 * 0.5, share1 = 0.5 * 0.5;  // of the total 2
  EXPECT_FLOAT_EQ(cdf[1], float(0.9 * share0 + 0.1 * 0.25));
  EXPECT_FLOAT_EQ(cdf[2] - cdf[1], float(0.9 * share1 + 0.1 * 0.25));
  EXPECT_FLOAT_EQ(cdf[3] - cdf[2], float(0.1 * 0.5));
  EXPECT_EQ(cdf[3], 1.0f);
  // q = (0.7, 0.25, 0.05) against p0 = (0.25, 0.25, 0.5): gain 2.215 / 1.29067 = 1.716 < 2.
  EXPECT_NEAR(emitter_fold_second_moment_gain(r, kEmitterFoldPatches, 3, 0.5f), 2.215 / 1.2906699, 1e-5);
  EXPECT_EQ(guided, 0.0f);
}

}  // namespace
}  // namespace exitance
