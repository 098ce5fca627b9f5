// The per-bounce mode's host side, shared by every backend (per_bounce_bake.h; issue 10). The
// layers' meaning is the estimator's (per_bounce_bake.h, cpu/cpu_bounce_integrator.cpp).
//
// Schedule: passes from the PassScheduler; a pass adds `count` samples to every layer in order,
// B_0 first, each layer's pages rebuilt before the next layer gathers from them (the gather is
// linear in the cache, so samples gathered from an earlier, noisier cache stay unbiased). After the
// last layer of a pass, a further layer is started within the same pass when --bounces asks for
// more, or (automatic) while the tail extrapolated from the last two layers is above the noise of
// the total (bounce_tail.h). spp N gives every layer N samples, in one pass; a time budget or a
// target error ramps passes of 1, 4 then 16 samples (PassPolicy::ramp) and the layers started late
// have fewer samples. The target error is tested on the whole lightmap (every texel's relative
// standard error below it, and the tail below the noise), not per texel.
//
// Noise: per layer, the variance of each texel's gather samples given the layer below; the total's
// variance is taken as their sum. That leaves out the noise of a cache propagated upward (spread
// over many texels, it acts at the scale of the scene, and shows as a correlated error), so the
// tracked variance underestimates the total's error and the tail criterion errs towards more bounces.
#include "exitance/runtime/core/per_bounce_bake.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "exitance/common/bounce_gather.h"
#include "exitance/runtime/core/bounce_tail.h"
#include "exitance/runtime/core/pass_scheduler.h"
#include "exitance/runtime/core/work_share.h"

namespace exitance {
namespace {

// B_0 .. B_256 at most; fewer when the layers' sums would pass ~2 GiB.
constexpr int kMaxLayers = 257;
constexpr size_t kLayerMemoryLimit = size_t(2) << 30;
// Rings of gutter texels filled around charts: a bilinear footprint reaches one texel past a chart.
constexpr int kCacheDilation = 2;
// Tails of ratios above this (a nearly white closed room) are not completed: r / (1 - r) would
// multiply the last bounce's noise by 19 or more; the stopping rule alone bounds their truncation.
constexpr double kMaxCompletedTailRatio = 0.95;

// Per texel sums of one layer's samples (RGB, doubles: long runs keep precision).
struct Layer {
  std::vector<double> sum, sum_squared;
  std::vector<uint32_t> back_faces;  // B_0 only: samples whose continuation ray met a back face
  uint32_t samples = 0;
  explicit Layer(size_t texels) : sum(texels * 3, 0.0), sum_squared(texels * 3, 0.0) {}
  Vec3 mean(size_t i) const {
    if (samples == 0) return {0, 0, 0};
    return {float(sum[i * 3] / samples), float(sum[i * 3 + 1] / samples), float(sum[i * 3 + 2] / samples)};
  }
  double variance_of_mean(size_t i, int c) const {
    if (samples < 2) return 0;
    const double n = samples, m = sum[i * 3 + size_t(c)] / n;
    return std::max(0.0, (sum_squared[i * 3 + size_t(c)] - n * m * m) / (n - 1)) / n;
  }
};

double area_of(const LiveTexel& t) {
  const double s = t.world_texel_size;
  return s > 0 && std::isfinite(s) ? s * s : 1.0;
}

BounceTail tail_after(const std::vector<Layer>& layers, const TexelGBuffer& gbuffer) {
  const size_t n = gbuffer.texels.size(), last = layers.size() - 1;
  BounceTailInputs in;
  in.area.resize(n);
  in.previous_bounce.resize(n);
  in.last_bounce.resize(n);
  in.previous_bounce_variance.resize(n);
  in.last_bounce_variance.resize(n);
  in.total.resize(n);
  in.total_variance.resize(n);
  // Variance of the luminance of a layer's mean, its channels taken as fully correlated (they are
  // nearly so: one ray lights all three).
  auto luminance_variance = [&](const Layer& layer, size_t i) {
    const double sd = luminance(Vec3(float(std::sqrt(layer.variance_of_mean(i, 0))), float(std::sqrt(layer.variance_of_mean(i, 1))),
                                     float(std::sqrt(layer.variance_of_mean(i, 2)))));
    return sd * sd;
  };
  for (size_t i = 0; i < n; ++i) {
    in.area[i] = area_of(gbuffer.texels[i]);
    in.previous_bounce[i] = luminance(layers[last - 1].mean(i));
    in.last_bounce[i] = luminance(layers[last].mean(i));
    in.previous_bounce_variance[i] = luminance_variance(layers[last - 1], i);
    in.last_bounce_variance[i] = luminance_variance(layers[last], i);
    Vec3 total{0, 0, 0}, variance{0, 0, 0};
    for (const Layer& layer : layers) {
      total += layer.mean(i);
      for (int c = 0; c < 3; ++c) variance[c] += float(layer.variance_of_mean(i, c));
    }
    in.total[i] = luminance(total);
    in.total_variance[i] = luminance(variance);
  }
  return estimate_bounce_tail(in);
}

}  // namespace

LightmapEstimate bake_per_bounce(const TexelGBuffer& gbuffer, const IntegratorSettings& settings,
                                 BounceLayerEstimator& estimator) {
  const auto start = std::chrono::steady_clock::now();
  const size_t n = gbuffer.texels.size();
  const bool forced = settings.max_bounces >= 0;
  int layer_cap = forced ? settings.max_bounces + 1 : std::min(kMaxLayers, std::max(settings.safety_bounce_cap, 1) + 1);
  layer_cap = int(std::min<size_t>(size_t(layer_cap), std::max<size_t>(2, kLayerMemoryLimit / (48 * std::max<size_t>(n, 1)))));

  std::vector<Layer> layers;
  std::vector<BounceLayerCache> caches;
  layers.emplace_back(n);
  layers[0].back_faces.assign(n, 0);
  caches.emplace_back();
  std::vector<uint64_t> cache_versions(1, 0);  // bumped at each rebuild: a device copy knows when it is stale
  // Texels whose B_0 rays mostly meet back faces are inside or under geometry (as the bake's scene
  // checks say): left out of every lookup (BounceLayerCache).
  std::vector<uint8_t> valid(n, 1);
  auto counters = [&] { return estimator.counts(); };
  BounceTail tail;
  bool tail_known = false;

  PassPolicy policy;
  policy.ramp = settings.time_budget_seconds > 0 || settings.target_relative_error > 0;
  PassScheduler passes(settings, policy);
  // Split over processes (work_share.h): each layer pass estimates this rank's texels, then every
  // rank gathers the layer's sums, so the caches, the tail and the stop are computed from the whole
  // layer, identically everywhere. The split follows the rays each texel traced in the last pass.
  WorkShare* share = distributed(settings.work_share);
  std::vector<size_t> bounds = share ? split_by_cost(n, {}, share->ranks()) : std::vector<size_t>{};
  std::vector<uint64_t> texel_rays(share ? n : 0);
  uint64_t own_samples = 0;
  std::vector<double> seconds_per_sample;  // per layer: the last pass's seconds per sample of every texel
  uint32_t first = 0, count = 0;
  while (passes.next_pass(first, count)) {
    bool wants_more = false;
    for (size_t k = 0; k < layers.size(); ++k) {
      Layer& layer = layers[k];
      uint32_t add = settings.spp > 0 ? std::min(count, settings.spp - std::min(settings.spp, layer.samples)) : count;
      // Under a time budget, a layer pass that would end past it takes the samples that fit, by this
      // layer's measured seconds per sample (every texel still gets the same count): the budget is
      // kept to about a pass of one sample rather than overrun by a whole ramped pass.
      bool cut = false;
      if (passes.timed() && k < seconds_per_sample.size() && seconds_per_sample[k] > 0) {
        const double left = settings.time_budget_seconds - passes.elapsed_seconds();
        add = uint32_t(std::clamp(std::floor(left / seconds_per_sample[k]), 0.0, double(add)));
        cut = true;
      }
      if (share && passes.timed()) {  // rank 0's clock decides
        struct {
          uint32_t add, cut;
        } decision{add, cut ? 1u : 0u};
        decision = agreed(*share, decision);
        add = decision.add, cut = decision.cut != 0;
      }
      if (cut && add == 0) break;
      const auto layer_start = std::chrono::steady_clock::now();
      const size_t own_begin = share ? bounds[size_t(share->rank())] : 0;
      const size_t own_end = share ? bounds[size_t(share->rank()) + 1] : n;
      BounceLayerPass pass;
      pass.layer = int(k);
      pass.begin = own_begin, pass.end = own_end;
      pass.first_sample = layer.samples, pass.samples = add;
      pass.sum = layer.sum.data(), pass.sum_squared = layer.sum_squared.data();
      pass.back_faces = k == 0 ? layer.back_faces.data() : nullptr;
      pass.texel_rays = share ? texel_rays.data() : nullptr;
      if (add > 0) estimator.estimate(pass, caches, cache_versions);
      if (share && add > 0) {  // `add` is the same on every rank
        share->work.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - layer_start).count();
        own_samples += uint64_t(own_end - own_begin) * add;
        allgather_items(*share, layer.sum.data(), 3, bounds);
        allgather_items(*share, layer.sum_squared.data(), 3, bounds);
        if (k == 0) allgather_items(*share, layer.back_faces.data(), 1, bounds);
        allgather_items(*share, texel_rays.data(), 1, bounds);
        bounds = split_by_cost(n, texel_rays, share->ranks());
      }
      layer.samples += add;
      if (seconds_per_sample.size() <= k) seconds_per_sample.resize(k + 1, 0.0);
      if (add > 0)
        seconds_per_sample[k] = std::chrono::duration<double>(std::chrono::steady_clock::now() - layer_start).count() / add;
      if (k == 0)
        for (size_t i = 0; i < n; ++i) valid[i] = 2 * layers[0].back_faces[i] <= layers[0].samples ? 1 : 0;
      std::vector<Vec3> means(n);
      for (size_t i = 0; i < n; ++i) means[i] = layer.mean(i);
      caches[k].build(gbuffer, means, valid, kCacheDilation);
      ++cache_versions[k];

      if (k + 1 == layers.size()) {  // the top layer: does the light bounce on?
        // The noise needs two samples in every layer; until then no layer beyond B_1 is started.
        const bool noise_known =
            std::all_of(layers.begin(), layers.end(), [](const Layer& l) { return l.samples >= 2; });
        if (k >= 1) {
          tail = tail_after(layers, gbuffer);
          tail_known = true;
        }
        const bool tail_above_noise = k >= 1 && (!noise_known || !tail.below_noise);
        const bool more = forced ? int(layers.size()) < layer_cap
                                 : (k == 0 || (noise_known && !tail.below_noise)) && int(layers.size()) < layer_cap;
        wants_more = wants_more || (!forced && tail_above_noise);
        if (more) {
          layers.emplace_back(n);
          caches.emplace_back();
          cache_versions.push_back(0);
        }
      }
      // After every layer pass: the fraction of the budget spent under --time (a pass holds every
      // layer, and on a large scene one pass can take most of the budget), else of the layers.
      if (settings.progress)
        settings.progress(passes.timed() ? std::min(1.0, passes.elapsed_seconds() / settings.time_budget_seconds)
                          : forced       ? double(k + 1) / double(layer_cap)
                                         : double(k + 1) / double(k + 2),
                          counters().rays);
      bool out_of_time = passes.timed() && passes.elapsed_seconds() >= settings.time_budget_seconds;
      if (share && passes.timed()) out_of_time = agreed(*share, out_of_time);
      if (out_of_time) break;
    }
    bool all_converged = false;
    // At least 16 samples, as in path mode; a texel that stayed black with no variance (inside
    // geometry) has met any target (a relative error of 0/0 would never end the run).
    if (settings.target_relative_error > 0 && !wants_more && layers[0].samples >= 16) {
      all_converged = true;
      for (size_t i = 0; i < n && all_converged; ++i) {
        Vec3 total{0, 0, 0}, variance{0, 0, 0};
        for (const Layer& layer : layers) {
          total += layer.mean(i);
          for (int c = 0; c < 3; ++c) variance[c] += float(layer.variance_of_mean(i, c));
        }
        const float lum = luminance(total);
        all_converged = std::sqrt(luminance(variance)) <= settings.target_relative_error * lum;
      }
    }
    passes.finish_pass(counters().rays, all_converged);
  }

  // A layer started but never sampled (the budget ended first) is dropped.
  while (layers.size() > 1 && layers.back().samples == 0) layers.pop_back();
  if (!tail_known && layers.size() >= 2) tail = tail_after(layers, gbuffer);

  // The bounces not run, added as the geometric tail B_k r / (1 - r) of the last one (automatic
  // bounce count only: --bounces N asks for exactly N). Without it the stop leaves a truncation bias
  // of up to kTailToNoise times the noise, always dark; with it what remains is the error of r.
  // Only when the tail criterion itself stopped the run, on layers of at least two samples: r is then
  // measured net of the noise and the tail added is at most about half the noise. A budget that ends
  // first (or spp 1, where r is noise) leaves the truncation as it is rather than extrapolate it.
  const bool noise_known = std::all_of(layers.begin(), layers.end(), [](const Layer& l) { return l.samples >= 2; });
  const bool complete_tail = !forced && layers.size() >= 2 && noise_known && tail.below_noise && tail.ratio > 0 &&
                             tail.ratio < kMaxCompletedTailRatio;
  const double tail_factor = complete_tail ? double(geometric_tail_factor(float(tail.ratio))) : 0.0;

  LightmapEstimate estimate;
  const int layer_count = int(layers.size());
  estimate.recorded_bounces = layer_count;
  estimate.texels.resize(n);
  estimate.bounces.assign(size_t(layer_count) * n * 3, 0.0);
  const double n0 = layers[0].samples;
  for (size_t i = 0; i < n; ++i) {
    TexelAccumulator& acc = estimate.texels[i];
    acc.samples = layers[0].samples;
    double total[3] = {0, 0, 0}, variance[3] = {0, 0, 0};
    for (int k = 0; k < layer_count; ++k) {
      const Layer& layer = layers[size_t(k)];
      const Vec3 mean = layer.mean(i);
      // The last recorded bounce carries the completed tail, so the bounces still sum to the total.
      const double scale = k == layer_count - 1 ? 1.0 + tail_factor : 1.0;
      for (int c = 0; c < 3; ++c) {
        // The layer's mean as a sum over the texel's B_0 samples, so mean_bounce() reads it back.
        estimate.bounces[(size_t(k) * n + i) * 3 + size_t(c)] = n0 * scale * mean[c];
        total[c] += scale * mean[c];
        variance[c] += scale * scale * layer.variance_of_mean(i, c);
      }
    }
    for (int c = 0; c < 3; ++c) {
      acc.total[c] = n0 * total[c];
      acc.direct[c] = n0 * layers[0].mean(i)[c];
      // Chosen so variance_of_mean() returns the summed layer variances.
      acc.total_squared[c] = n0 * total[c] * total[c] + (n0 >= 2 ? (n0 - 1) * n0 * variance[c] : 0.0);
    }
  }
  BounceGatherCounts c = counters();
  if (settings.work_share) {
    RankWork& work = settings.work_share->work;
    work.rays += c.rays;
    if (share) {
      work.texel_samples += own_samples;
    } else {
      for (const Layer& layer : layers) work.texel_samples += uint64_t(layer.samples) * n;
      work.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
  }
  if (share) {
    c.rays = share->sum(c.rays), c.gathers = share->sum(c.gathers), c.texelless = share->sum(c.texelless);
    c.back_faces = share->sum(c.back_faces), c.nonfinite = share->sum(c.nonfinite);
  }
  BounceGatherStatistics& stats = estimate.bounce_statistics;
  stats.bounces = layer_count - 1;
  for (const Layer& layer : layers) stats.samples.push_back(layer.samples);
  stats.gathers = c.gathers;
  stats.texelless_hits = c.texelless;
  stats.back_face_hits = c.back_faces;
  stats.ratio = tail.ratio;
  stats.tail_rms = tail.tail_rms;
  stats.noise_rms = tail.noise_rms;
  stats.tail_below_noise = layer_count >= 2 && tail.below_noise;
  stats.tail_completed = complete_tail;
  estimate.rays = c.rays;
  estimate.nonfinite_samples = c.nonfinite;
  estimate.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return estimate;
}

}  // namespace exitance
