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
// standard error below it, and the tail below the noise), not per texel. A layer's cache is built
// when a gather is about to read it (every cache below the layer, as texelless hits recurse), so a
// top layer's or a last pass's cache is never built for nothing; the results are those of building
// each after its layer's pass.
//
// Time budget: each layer pass takes what fits of its samples at that layer's measured seconds per
// sample, after the caches it reads are rebuilt (at their last build's time) and with the work
// after the loop kept aside (kAfterLoopPerTail times the last tail's time). The first layer
// pass that does not fit whole is the last of the bake: its whole samples, then one more sample for
// the fraction of the texels the time left pays for (core/partial_layer_pass.h), so the bake ends
// within a small part of one layer sample of the budget. When not one sample of that layer fits
// past its caches' rebuild, the time goes to B_0, which reads no cache. Each texel's layer is the
// mean of its own samples (counts differ by at most one), so the partial pass adds no bias.
//
// Noise: per layer, the variance of each texel's gather samples given the layer below; the total's
// variance is taken as their sum. That leaves out the noise of a cache propagated upward (spread
// over many texels, it acts at the scale of the scene, and shows as a correlated error), so the
// tracked variance underestimates the total's error and the tail criterion errs towards more bounces.
#include "exitance/runtime/core/per_bounce_bake.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>

#include "exitance/common/bounce_gather.h"
#include "exitance/common/gpu_layout.h"
#include "exitance/formats/huge_pages.h"
#include "exitance/runtime/core/bounce_tail.h"
#include "exitance/runtime/core/partial_layer_pass.h"
#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance/runtime/core/pass_scheduler.h"
#include "exitance/runtime/core/work_share.h"

namespace exitance {
namespace {

// B_0 .. B_256 at most; fewer when the layers' sums would pass ~2 GiB.
constexpr int kMaxLayers = 257;
constexpr size_t kLayerMemoryLimit = size_t(2) << 30;
// Rings of gutter texels filled around charts (gpu_layout.h: the device's builder fills as many).
constexpr int kCacheDilation = int(kBounceCacheDilation);
// What a time budget keeps aside for the work after the last layer pass, in tail estimates (of as
// many layers): the assembly reads every layer of every texel once, as the tail does, and freeing
// the layers and the caller's copy of the result (bake's expansion onto the sealed texels) cost
// about as much again (Cornell room, 478 k texels, 2 cores: tail 0.044-0.063 s, assembly
// 0.03-0.05 s, frees and expansion 0.06-0.08 s; all after the last layer pass 0.11-0.14 s against
// 0.09-0.12 s kept aside).
constexpr double kAfterLoopPerTail = 2.0;
// Tails of ratios above this (a nearly white closed room) are not completed: r / (1 - r) would
// multiply the last bounce's noise by 19 or more; the stopping rule alone bounds their truncation.
constexpr double kMaxCompletedTailRatio = 0.95;

// `count` zeros, first touched on all cores and in huge pages where the kernel allows: a layer's
// sums are 48 MB at 1 M texels, and what zeroing them costs is the page faults, not the writes.
std::unique_ptr<double[]> zeros_on_all_cores(size_t count) {
  std::unique_ptr<double[]> values = std::make_unique_for_overwrite<double[]>(count);
  formats::advise_huge_pages(values.get(), count * sizeof(double));
  for_each_chunk(count, [&](size_t begin, size_t end) { std::fill(values.get() + begin, values.get() + end, 0.0); }, 1 << 18);
  return values;
}

// Per texel sums of one layer's samples (RGB, doubles: long runs keep precision).
struct Layer {
  std::unique_ptr<double[]> sum, sum_squared;
  std::vector<uint32_t> back_faces;  // B_0 only: samples whose continuation ray met a back face
  uint32_t samples = 0;  // every texel's
  // Empty, or per texel 1 where the partial last pass of a time budget gave it sample `samples` too.
  std::vector<uint8_t> one_more;
  explicit Layer(size_t texels) : sum(zeros_on_all_cores(texels * 3)), sum_squared(zeros_on_all_cores(texels * 3)) {}
  uint32_t samples_at(size_t i) const { return samples + (one_more.empty() ? 0u : uint32_t(one_more[i])); }
  Vec3 mean(size_t i) const {
    const uint32_t count = samples_at(i);
    if (count == 0) return {0, 0, 0};
    return {float(sum[i * 3] / count), float(sum[i * 3 + 1] / count), float(sum[i * 3 + 2] / count)};
  }
  double variance_of_mean(size_t i, int c) const {
    const uint32_t count = samples_at(i);
    if (count < 2) return 0;
    const double n = count, m = sum[i * 3 + size_t(c)] / n;
    return std::max(0.0, (sum_squared[i * 3 + size_t(c)] - n * m * m) / (n - 1)) / n;
  }
  uint64_t texels_with_one_more() const { return uint64_t(std::count(one_more.begin(), one_more.end(), uint8_t(1))); }
};

// Texel i's total over the layers, and its variance (the layers' variances summed).
Vec3 total_of(const std::vector<Layer>& layers, size_t i) {
  Vec3 total{0, 0, 0};
  for (const Layer& layer : layers) total += layer.mean(i);
  return total;
}
Vec3 total_variance_of(const std::vector<Layer>& layers, size_t i) {
  Vec3 variance{0, 0, 0};
  for (const Layer& layer : layers)
    for (int c = 0; c < 3; ++c) variance[c] += float(layer.variance_of_mean(i, c));
  return variance;
}

double area_of(const LiveTexel& t) {
  const double s = t.world_texel_size;
  return s > 0 && std::isfinite(s) ? s * s : 1.0;
}

// What one tail keeps for the next (every entry of `inputs` is written by each tail; allocated per
// tail, its seven arrays were 56 MB of fresh pages to fault in each time at 1 M texels).
struct TailState {
  BounceTailInputs inputs;
  bool areas_known = false;  // inputs.area: the G-buffer's, the same for every tail of a bake
  // Per texel, the sum over layers [0, prefix_samples.size()) of their means and of their means'
  // variances, added in layer order in float as total_of / total_variance_of add them (so a total
  // from the prefix is the same bits), while those layers' sample counts are prefix_samples (a layer
  // with a partial pass's extra samples is never kept). A tail then reads the prefix and the top two
  // layers, not every layer: the Cornell room's tails 0.256 -> 0.206 s on 2 cores; no measurable
  // change on a 16-thread GPU host (bench/results/per-bounce-gpu.md).
  std::vector<Vec3> prefix_total, prefix_variance;
  std::vector<uint32_t> prefix_samples;
};

BounceTail tail_after(const std::vector<Layer>& layers, const TexelGBuffer& gbuffer, TailState& state) {
  const size_t n = gbuffer.texels.size(), last = layers.size() - 1;
  BounceTailInputs& in = state.inputs;
  for (std::vector<double>* v : {&in.area, &in.previous_bounce, &in.last_bounce, &in.previous_bounce_variance,
                                 &in.last_bounce_variance, &in.total, &in.total_variance})
    v->resize(n);
  if (!state.areas_known) {
    for_each_chunk(n, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) in.area[i] = area_of(gbuffer.texels[i]);
    }, 16384);
    state.areas_known = true;
  }
  // The prefix holds layers [0, kept) still as they are; it grows to [0, last) below.
  size_t kept = 0;
  while (kept < state.prefix_samples.size() && kept < last && layers[kept].one_more.empty() &&
         layers[kept].samples == state.prefix_samples[kept])
    ++kept;
  if (kept < state.prefix_samples.size() || state.prefix_total.size() != n) {  // a cached layer changed: from layer 0 again
    kept = 0;
    state.prefix_total.assign(n, Vec3{0, 0, 0});
    state.prefix_variance.assign(n, Vec3{0, 0, 0});
  }
  state.prefix_samples.resize(kept);
  for (size_t k = kept; k < last; ++k) state.prefix_samples.push_back(layers[k].samples);
  // Variance of the luminance of a layer's mean, its channels taken as fully correlated (they are
  // nearly so: one ray lights all three).
  auto luminance_variance = [&](const Layer& layer, size_t i) {
    const double sd = luminance(Vec3(float(std::sqrt(layer.variance_of_mean(i, 0))), float(std::sqrt(layer.variance_of_mean(i, 1))),
                                     float(std::sqrt(layer.variance_of_mean(i, 2)))));
    return sd * sd;
  };
  auto add_layer = [](const Layer& layer, size_t i, Vec3& total, Vec3& variance) {
    total += layer.mean(i);
    for (int c = 0; c < 3; ++c) variance[c] += float(layer.variance_of_mean(i, c));
  };
  // Each texel's inputs on its own (all cores: at 1 M texels and ten layers this was most of the
  // host's time between the GPU's layer passes); the reduction stays serial, in texel order.
  for_each_chunk(n, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      Vec3 total = state.prefix_total[i], variance = state.prefix_variance[i];
      for (size_t k = kept; k < last; ++k) add_layer(layers[k], i, total, variance);
      state.prefix_total[i] = total, state.prefix_variance[i] = variance;
      add_layer(layers[last], i, total, variance);
      in.previous_bounce[i] = luminance(layers[last - 1].mean(i));
      in.last_bounce[i] = luminance(layers[last].mean(i));
      in.previous_bounce_variance[i] = luminance_variance(layers[last - 1], i);
      in.last_bounce_variance[i] = luminance_variance(layers[last], i);
      in.total[i] = luminance(total);
      in.total_variance[i] = luminance(variance);
    }
  }, 16384);
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

  PassPolicy policy;
  policy.ramp = settings.time_budget_seconds > 0 || settings.target_relative_error > 0;
  policy.caller_cuts_last_pass = true;  // per layer, down to a part of the texels (below)
  PassScheduler passes(settings, policy);

  // The result's arrays are allocated as the layers are (their first touch costs about as much as
  // filling them), so the assembly after the loop only writes: less of it is left past the budget.
  // The layer rows are reserved for the layer cap at once (address space, half of kLayerMemoryLimit):
  // growing them a layer at a time re-copied and re-faulted every earlier row (0.4 of the 0.6 s
  // outside the timed parts of a 2-spp Cornell run on lavapipe, 2 cores).
  LightmapEstimate estimate;
  formats::resize_in_huge_pages(estimate.texels, n);  // 80 MB at 1 M texels
  std::vector<Layer> layers;
  std::vector<BounceLayerCache> caches;
  std::vector<uint64_t> cache_versions;  // bumped at each rebuild: a device copy knows when it is stale
  std::vector<uint8_t> cache_stale;      // samples (or texel validity) changed since the cache was built
  std::vector<double> cache_seconds;     // its last build's
  auto add_layer = [&] {
    layers.emplace_back(n);
    caches.emplace_back();
    cache_versions.push_back(0);
    cache_stale.push_back(1);
    cache_seconds.push_back(0.0);
    estimate.bounces.resize(layers.size() * n * 3, 0.0);
  };
  estimate.bounces.reserve(size_t(layer_cap) * n * 3);
  formats::advise_huge_pages(estimate.bounces.data(), estimate.bounces.capacity() * sizeof(double));
  add_layer();
  layers[0].back_faces.assign(n, 0);
  // Texels whose B_0 rays mostly meet back faces are inside or under geometry (as the bake's scene
  // checks say): left out of every lookup (BounceLayerCache).
  std::vector<uint8_t> valid(n, 1);
  auto counters = [&] { return estimator.counts(); };
  BounceTail tail;
  TailState tail_state;
  bool tail_known = false;
  double tail_seconds = 0;  // the last tail's, over tail_layers layers: sizes the work after the loop
  size_t tail_layers = 0;
  auto assembly_seconds = [&] {
    return tail_layers > 0 ? kAfterLoopPerTail * tail_seconds * double(layers.size()) / double(tail_layers) : 0.0;
  };
  BounceGatherStatistics::Seconds host;  // the loop's parts (estimates.h)
  std::vector<Vec3> means;  // the layer a cache is built from: kept from one build to the next
  size_t last_built = SIZE_MAX;  // the cache built last: its plan (cells, rings) serves the next while validity stays
  auto build_cache = [&](size_t k) {
    const double build_start = passes.elapsed_seconds();
    means.resize(n);
    for_each_chunk(n, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) means[i] = layers[k].mean(i);
    });
    if (estimator.builds_caches())
      estimator.build_cache(k, means, valid);
    else
      caches[k].build(gbuffer, means, valid, kCacheDilation, last_built < caches.size() ? &caches[last_built] : nullptr);
    last_built = k;
    ++cache_versions[k];
    cache_stale[k] = 0;
    cache_seconds[k] = passes.elapsed_seconds() - build_start;
    host.caches += cache_seconds[k];
  };

  // Split over processes (work_share.h): each layer pass estimates this rank's texels, then every
  // rank gathers the layer's sums, so the caches, the tail and the stop are computed from the whole
  // layer, identically everywhere. The split follows the rays each texel traced in the last pass.
  WorkShare* share = distributed(settings.work_share);
  std::vector<size_t> bounds = share ? split_by_cost(n, {}, share->ranks()) : std::vector<size_t>{};
  std::vector<uint64_t> texel_rays(share ? n : 0);
  uint64_t own_samples = 0;
  std::vector<double> seconds_per_sample;  // per layer: its last whole pass's seconds per sample of every texel
  bool budget_ends = false;                // the last layer pass of the time budget has run
  uint32_t first = 0, count = 0;
  while (!budget_ends && passes.next_pass(first, count)) {
    bool wants_more = false;
    for (size_t k = 0; k < layers.size(); ++k) {
      const uint32_t wanted =
          settings.spp > 0 ? std::min(count, settings.spp - std::min(settings.spp, layers[k].samples)) : count;
      // What runs: `whole` samples of layer `layer` (k, or B_0 when the budget ends and not one sample
      // of k fits past its caches' rebuild), then one more for `fraction` of the texels.
      struct Step {
        uint32_t layer, whole;
        double fraction;
        uint32_t ends;  // the budget ends with this step
      } step{uint32_t(k), wanted, 0.0, 0u};
      // A layer not yet measured costs about what the one below it cost (B_1 excepted: it runs in
      // the first pass, and its traced direct light makes it dearer than B_0).
      const double per_sample = k < seconds_per_sample.size() && seconds_per_sample[k] > 0 ? seconds_per_sample[k]
                                : k >= 2 && k - 1 < seconds_per_sample.size()          ? seconds_per_sample[k - 1]
                                                                                       : 0.0;
      if (passes.timed() && per_sample > 0) {
        double caches_first = 0;
        for (size_t j = 0; j < k; ++j) caches_first += cache_stale[j] ? cache_seconds[j] : 0.0;
        const double left = settings.time_budget_seconds - passes.elapsed_seconds() - assembly_seconds();
        LayerPassCut cut = cut_layer_pass(left - caches_first, per_sample, wanted);
        // No partial first sample: a texel without one would read the layer as 0.
        if (layers[k].samples == 0) cut.fraction = 0;
        if (cut.cut && cut.whole == 0 && caches_first > 0 && seconds_per_sample[0] > 0) {
          const uint32_t room = settings.spp > 0 ? settings.spp - std::min(settings.spp, layers[0].samples)
                                                 : 0xFFFFFFFFu - layers[0].samples;
          cut = cut_layer_pass(left, seconds_per_sample[0], room);
          step.layer = 0;
        }
        step.whole = cut.whole, step.fraction = cut.fraction, step.ends = cut.cut ? 1u : 0u;
      }
      if (share && passes.timed()) step = agreed(*share, step);  // rank 0's clock decides
      budget_ends = step.ends != 0;

      const size_t t = step.layer;
      Layer& layer = layers[t];
      const size_t own_begin = share ? bounds[size_t(share->rank())] : 0;
      const size_t own_end = share ? bounds[size_t(share->rank()) + 1] : n;
      const bool runs = step.whole > 0 || step.fraction > 0;
      if (runs)
        for (size_t j = 0; j < t; ++j)
          if (cache_stale[j]) build_cache(j);
      BounceLayerPass pass;
      pass.layer = int(t);
      pass.begin = own_begin, pass.end = own_end;
      pass.sum = layer.sum.get(), pass.sum_squared = layer.sum_squared.get();
      pass.back_faces = t == 0 ? layer.back_faces.data() : nullptr;
      pass.texel_rays = share ? texel_rays.data() : nullptr;
      const double layer_start = passes.elapsed_seconds();
      if (step.whole > 0) {
        pass.first_sample = layer.samples, pass.samples = step.whole;
        estimator.estimate(pass, caches, cache_versions);
        host.passes += passes.elapsed_seconds() - layer_start;
        if (share) share->work.seconds += passes.elapsed_seconds() - layer_start;
        own_samples += uint64_t(own_end - own_begin) * step.whole;
      }
      if (step.fraction > 0) {  // the budget's last pass: one more sample for part of the texels
        const PartialPassTexels chosen(step.fraction, settings.seed, int(t), layer.samples + step.whole);
        const std::vector<uint32_t> own = chosen.in_range(own_begin, own_end);
        const double partial_start = passes.elapsed_seconds();
        pass.first_sample = layer.samples + step.whole, pass.samples = 1, pass.texels = &own;
        if (!own.empty()) estimator.estimate(pass, caches, cache_versions);
        host.passes += passes.elapsed_seconds() - partial_start;
        if (share) share->work.seconds += passes.elapsed_seconds() - partial_start;
        own_samples += own.size();
        layer.one_more.resize(n);  // every rank marks every texel: the choice is by global index
        for (size_t i = 0; i < n; ++i) layer.one_more[i] = chosen.covers(i) ? 1 : 0;
      }
      if (share && runs) {  // `step` is the same on every rank
        allgather_items(*share, layer.sum.get(), 3, bounds);
        allgather_items(*share, layer.sum_squared.get(), 3, bounds);
        if (t == 0) allgather_items(*share, layer.back_faces.data(), 1, bounds);
        allgather_items(*share, texel_rays.data(), 1, bounds);
        bounds = split_by_cost(n, texel_rays, share->ranks());
      }
      if (step.whole > 0 && step.fraction == 0) {  // whole passes only, the exchange included
        if (seconds_per_sample.size() <= t) seconds_per_sample.resize(t + 1, 0.0);
        seconds_per_sample[t] = (passes.elapsed_seconds() - layer_start) / step.whole;
      }
      layer.samples += step.whole;
      if (runs) cache_stale[t] = 1;
      if (t == 0 && runs) {  // texel validity changes every cache
        for_each_chunk(n, [&](size_t begin, size_t end) {
          for (size_t i = begin; i < end; ++i) valid[i] = 2 * layers[0].back_faces[i] <= layers[0].samples_at(i) ? 1 : 0;
        });
        std::fill(cache_stale.begin(), cache_stale.end(), uint8_t(1));
      }

      if (!budget_ends && k + 1 == layers.size()) {  // the top layer: does the light bounce on?
        // The noise needs two samples in every layer; until then no layer beyond B_1 is started.
        const bool noise_known =
            std::all_of(layers.begin(), layers.end(), [](const Layer& l) { return l.samples >= 2; });
        if (k >= 1) {
          const double tail_start = passes.elapsed_seconds();
          tail = tail_after(layers, gbuffer, tail_state);
          tail_known = true;
          tail_seconds = passes.elapsed_seconds() - tail_start, tail_layers = layers.size();
          host.tail += tail_seconds;
        }
        const bool tail_above_noise = k >= 1 && (!noise_known || !tail.below_noise);
        const bool more = forced ? int(layers.size()) < layer_cap
                                 : (k == 0 || (noise_known && !tail.below_noise)) && int(layers.size()) < layer_cap;
        wants_more = wants_more || (!forced && tail_above_noise);
        if (more) add_layer();
      }
      // After every layer pass: the fraction of the budget spent under --time (a pass holds every
      // layer, and on a large scene one pass can take most of the budget), else of the layers.
      if (settings.progress)
        settings.progress(passes.timed() ? std::min(1.0, passes.elapsed_seconds() / settings.time_budget_seconds)
                          : forced       ? double(k + 1) / double(layer_cap)
                                         : double(k + 1) / double(k + 2),
                          counters().rays);
      if (budget_ends) break;
      bool out_of_time = passes.timed() && passes.elapsed_seconds() >= settings.time_budget_seconds;
      if (share && passes.timed()) out_of_time = agreed(*share, out_of_time);
      // B_1 gets its first sample even past the budget: without it the lightmap would hold direct
      // light only, no estimate of E at all wherever light arrives by a bounce (the open city at 2
      // texels/m under --time 2 on 2 cores: B_0's first pass alone took the budget). The bake warns
      // of the overrun (lighting_stage, bake/command/bake_stages.cpp).
      const bool first_bounce_unsampled = k == 0 && layers.size() > 1 && layers[1].samples == 0;
      if (out_of_time && !first_bounce_unsampled) break;
    }
    bool all_converged = false;
    // At least 16 samples, as in path mode; a texel that stayed black with no variance (inside
    // geometry) has met any target (a relative error of 0/0 would never end the run).
    if (settings.target_relative_error > 0 && !wants_more && layers[0].samples >= 16) {
      const double test_start = passes.elapsed_seconds();
      std::atomic<bool> converged{true};
      for_each_chunk(n, [&](size_t begin, size_t end) {
        for (size_t i = begin; i < end && converged.load(std::memory_order_relaxed); ++i)
          if (!(std::sqrt(luminance(total_variance_of(layers, i))) <= settings.target_relative_error * luminance(total_of(layers, i))))
            converged.store(false, std::memory_order_relaxed);
      }, 16384);
      all_converged = converged.load();
      host.tail += passes.elapsed_seconds() - test_start;
    }
    passes.finish_pass(counters().rays, all_converged);
  }

  // A layer started but never sampled (the budget ended first) is dropped.
  const double assembly_start = passes.elapsed_seconds();
  while (layers.size() > 1 && layers.back().samples == 0) layers.pop_back();
  if (!tail_known && layers.size() >= 2) tail = tail_after(layers, gbuffer, tail_state);

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

  const int layer_count = int(layers.size());
  estimate.recorded_bounces = layer_count;
  estimate.bounces.resize(size_t(layer_count) * n * 3);  // every entry is written below
  for_each_chunk(n, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      TexelAccumulator& acc = estimate.texels[i];
      acc.samples = layers[0].samples_at(i);
      const double n0 = acc.samples;
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
  }, 16384);
  BounceGatherCounts c = counters();
  if (settings.work_share) {
    RankWork& work = settings.work_share->work;
    work.rays += c.rays;
    if (share) {
      work.texel_samples += own_samples;
    } else {
      for (const Layer& layer : layers) work.texel_samples += uint64_t(layer.samples) * n + layer.texels_with_one_more();
      work.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
  }
  if (share) {
    c.rays = share->sum(c.rays), c.gathers = share->sum(c.gathers), c.texelless = share->sum(c.texelless);
    c.back_faces = share->sum(c.back_faces), c.nonfinite = share->sum(c.nonfinite);
  }
  BounceGatherStatistics& stats = estimate.bounce_statistics;
  stats.bounces = layer_count - 1;
  for (const Layer& layer : layers) {
    stats.samples.push_back(layer.samples);
    stats.texels_with_one_more.push_back(layer.texels_with_one_more());
  }
  stats.gathers = c.gathers;
  stats.texelless_hits = c.texelless;
  stats.back_face_hits = c.back_faces;
  stats.ratio = tail.ratio;
  stats.tail_rms = tail.tail_rms;
  stats.noise_rms = tail.noise_rms;
  stats.tail_below_noise = layer_count >= 2 && tail.below_noise;
  stats.tail_completed = complete_tail;
  host.assembly = passes.elapsed_seconds() - assembly_start;
  stats.seconds = host;
  estimate.rays = c.rays;
  estimate.nonfinite_samples = c.nonfinite;
  estimate.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return estimate;
}

}  // namespace exitance
