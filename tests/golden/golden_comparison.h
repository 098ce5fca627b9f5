// The golden test's statistic and its tolerance (docs/view.md, "Golden tests"): relMSE between the view
// drawn from a baked bundle and a path-traced view of the same camera, against what that relMSE is
// expected to be when the bundle is right, derived from both images' own noise and the lightmap's
// texel resolution. Nothing here is tuned to a scene.
//
// Per pixel p and channel c (pixels whose instance is lit from its lightmap), with a = albedo,
// B = the baked view's value, R = the path-traced one, d = B - R:
//   E[d^2] = Var[R] + Var[B] + bias^2 (the two estimates are independent).
// - Var[R] = a^2 Var[mean E/pi], the path tracer's own sample variance of the pixel's mean.
// - Var[B] = a^2 sum_k beta_k^2 SE_k^2 over the four bilinear taps k (weights beta_k), texel noise being
//   independent between texels; SE_k from the bundle's error.Y layer: error.Y = SE_Y / (Y + floor)
//   (docs/lighting-core.md, "Outputs"), so SE_Y = error.Y (Y + floor), and each channel is given
//   the luminance's relative error (SE_c = SE_Y c / Y; the layer stores luminance only).
// - bias: the lightmap holds E/pi at texel centres and the view interpolates between them; the
//   difference from E/pi at the pixel's own point is bounded by the lightmap's gradient times half a
//   texel, taken as half the spread (max - min) of the four taps, per channel: bias <= a spread / 2.
//   (A bilinear lookup of a linear function is exact; this bounds what curvature, shadow edges and
//   the unocclude push can add inside one texel cell. The taps' own noise widens the spread, which
//   only loosens the bound.)
// The statistic is relMSE = mean over (p, c) of w d^2 with w = 1 / (R^2 + eps^2), eps^2 = 1e-3 x the
// mean of R^2 (the bench's regularizer for dark pixels); its expectation under a right bundle is at
// most mean(w (Var[R] + Var[B] + bias^2)), treating w as fixed (its own noise is second order: the
// pixels' relative noise is a few percent). Its spread: d^2 of a normal variable has variance
// 2 v^2 + 4 b^2 v (v its variance, b its mean); pixels that read the same texels share their lightmap
// noise, so the pixels are grouped by their nearest texel, terms inside a group taken as fully
// correlated and groups independent, and the variance doubled for the neighbouring groups a bilinear
// lookup also reads (conservative). Tolerance = expectation + 4 standard deviations.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <tuple>
#include <vector>

#include "exitance/formats/lightmap_exr.h"
#include "exitance/runtime/view/path_traced_view.h"
#include "exitance/runtime/view/view_render.h"
#include "exitance/runtime/view/view_shading.h"

namespace exitance::testing {

struct GoldenComparison {
  double rel_mse = 0;          // the statistic
  double expected_noise = 0;   // mean w (Var[R] + Var[B])
  double expected_path_noise = 0;  // its Var[R] part
  double bias_bound = 0;       // mean w bias^2
  double spread = 0;           // standard deviation of the statistic
  double tolerance = 0;        // expected_noise + bias_bound + 4 spread
  size_t pixels = 0;           // pixels compared (lit from a lightmap)
  size_t other_pixels = 0;     // misses, absorbing back faces, instances without texels (not compared)
};

namespace golden_detail {

// The loader's bilinear taps along one axis (runtime/loader/src/lightmap_lookup.cpp): texel centres on
// integers, clamp to edge.
struct Taps {
  int i0, i1;
  double t;
};
inline Taps axis_taps(double page_coordinate, int texels) {
  const double x = std::clamp(page_coordinate * texels - 0.5, 0.0, double(texels - 1));
  const int i0 = std::min(int(std::floor(x)), texels - 1);
  return {i0, std::min(i0 + 1, texels - 1), x - i0};
}

inline float luminance(const float* rgb) { return 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2]; }

}  // namespace golden_detail

// `error_floor`: the bundle's stats.error.floor (manifest.json).
inline GoldenComparison compare_with_path_traced(const view::ViewScene& scene, const view::PinholeCamera& camera,
                                                 const view::ViewImage& baked, const view::PathTracedView& traced,
                                                 double error_floor) {
  using namespace golden_detail;
  GoldenComparison g;
  const int w = baked.width, h = baked.height;
  struct Term {
    double d2, weight, noise, path_noise, bias2;
    std::tuple<uint32_t, int, int> group;
  };
  std::vector<Term> terms;
  double mean_r2 = 0;
  view::RayScratch scratch;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Vec3 dir = view::primary_ray_direction(camera, x + 0.5, y + 0.5, w, h);
      const std::optional<view::SurfaceAtHit> hit = view::first_surface(scene, camera.eye, dir, scratch);
      if (!hit || hit->back_face_absorbs || !scene.instance_has_texels[hit->instance]) {
        ++g.other_pixels;
        continue;
      }
      ++g.pixels;
      const formats::InstanceInfo& instance = scene.bundle.instances()[hit->instance];
      const formats::LightmapImage& page = scene.bundle.page_image(instance.page);
      const std::array<float, 4>& so = instance.scale_offset;
      const Taps tx = axis_taps(double(hit->lightmap_uv[0]) * so[0] + so[2], page.width);
      const Taps ty = axis_taps(double(hit->lightmap_uv[1]) * so[1] + so[3], page.height);
      const size_t tap_index[4] = {size_t(ty.i0) * page.width + tx.i0, size_t(ty.i0) * page.width + tx.i1,
                                   size_t(ty.i1) * page.width + tx.i0, size_t(ty.i1) * page.width + tx.i1};
      const double beta[4] = {(1 - tx.t) * (1 - ty.t), tx.t * (1 - ty.t), (1 - tx.t) * ty.t, tx.t * ty.t};
      const std::vector<float>* rgb[3] = {&page.channels.at("R"), &page.channels.at("G"), &page.channels.at("B")};
      const std::vector<float>& error = page.channels.at(view::kErrorChannel);
      const size_t p = size_t(y) * size_t(w) + size_t(x);
      const auto group = std::make_tuple(instance.page, int(std::lround(tx.i0 + tx.t)), int(std::lround(ty.i0 + ty.t)));
      for (int c = 0; c < 3; ++c) {
        double lightmap_variance = 0, lo = INFINITY, hi = -INFINITY;
        for (int k = 0; k < 4; ++k) {
          const size_t i = tap_index[k];
          const float texel[3] = {(*rgb[0])[i], (*rgb[1])[i], (*rgb[2])[i]};
          const double y_lum = luminance(texel), value = texel[c];
          const double se_y = double(error[i]) * (y_lum + error_floor);
          const double se = y_lum > 0 ? se_y * value / y_lum : se_y;
          lightmap_variance += beta[k] * beta[k] * se * se;
          lo = std::min(lo, value), hi = std::max(hi, value);
        }
        const double a = hit->albedo[c];
        const double b = baked.rgb[p * 3 + size_t(c)], r = traced.image.rgb[p * 3 + size_t(c)];
        const double path_variance = traced.variance[p * 3 + size_t(c)];
        const double half_spread = a * (hi - lo) / 2;
        terms.push_back({(b - r) * (b - r), r * r, a * a * lightmap_variance + path_variance, path_variance,
                         half_spread * half_spread, group});
        mean_r2 += r * r;
      }
    }
  if (terms.empty()) return g;
  mean_r2 /= double(terms.size());
  const double eps2 = 1e-3 * mean_r2;
  std::map<std::tuple<uint32_t, int, int>, double> group_sd;  // sum of the terms' standard deviations
  for (Term& t : terms) {
    t.weight = 1 / (t.weight + eps2);
    g.rel_mse += t.weight * t.d2;
    g.expected_noise += t.weight * t.noise;
    g.expected_path_noise += t.weight * t.path_noise;
    g.bias_bound += t.weight * t.bias2;
    group_sd[t.group] += t.weight * std::sqrt(2 * t.noise * t.noise + 4 * t.bias2 * t.noise);
  }
  const double n = double(terms.size());
  double variance = 0;
  for (const auto& entry : group_sd) variance += entry.second * entry.second;
  g.rel_mse /= n, g.expected_noise /= n, g.expected_path_noise /= n, g.bias_bound /= n;
  g.spread = std::sqrt(2 * variance) / n;
  g.tolerance = g.expected_noise + g.bias_bound + 4 * g.spread;
  return g;
}

inline void print_golden(const char* what, const GoldenComparison& g) {
  std::printf("[golden] %-34s pixels %zu (+%zu not compared) relMSE %.3g tolerance %.3g = noise %.3g (path %.3g) + bias bound %.3g + 4 x %.3g\n",
              what, g.pixels, g.other_pixels, g.rel_mse, g.tolerance, g.expected_noise, g.expected_path_noise, g.bias_bound,
              g.spread);
}

}  // namespace exitance::testing
