// The per-bounce mode (IntegratorMode::Bounces, issue 10; seed 003 ch. 3-4) for every backend: the
// host side - layers B_0..B_K, their schedule, the tail criterion and the completed tail, the
// dilated caches the gathers read, the split over processes, the statistics - lives here once; a
// backend supplies only the estimator of one layer pass (BounceLayerEstimator): the CPU reference
// on Embree (cpu/cpu_bounce_integrator.cpp), the Vulkan wavefront (vulkan/bounce_layer_driver.cpp).
// See per_bounce_bake.cpp for the schedule and docs/lighting-core.md for the bias of the lookup.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "exitance/runtime/core/bounce_layer_cache.h"
#include "exitance/runtime/core/estimates.h"
#include "exitance/runtime/core/integrator_settings.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

// Samples [first_sample, first_sample + samples) of layer `layer` at texels [begin, end) of the
// G-buffer, added to the layer's per-texel sums (RGB; arrays over the whole G-buffer).
struct BounceLayerPass {
  int layer = 0;  // 0: direct light at the texel; k >= 1: one gather ray reading B_{k-1}
  size_t begin = 0, end = 0;
  // Null: every texel of [begin, end). Else only these (ascending, within [begin, end)): the partial
  // last pass of a time budget (core/partial_layer_pass.h); the others' sums are left alone.
  const std::vector<uint32_t>* texels = nullptr;
  uint32_t first_sample = 0, samples = 0;
  double* sum = nullptr;
  double* sum_squared = nullptr;
  uint32_t* back_faces = nullptr;  // layer 0: per texel, samples whose continuation ray met a single-sided back face
  uint64_t* texel_rays = nullptr;  // null, or per texel the rays this pass traced (the split over processes)
};

// What the layer passes counted, summed over the bake so far.
struct BounceGatherCounts {
  uint64_t rays = 0, gathers = 0, texelless = 0, back_faces = 0, nonfinite = 0;
};

// One backend's estimator of the layers. A sample of B_0(x) is path.h's estimator cut at direct
// light; a sample of B_{k+1}(x) is a cosine ray whose hit y adds albedo(y) B_k(y), B_k(y) read from
// caches[k] (BounceLayerCache::lookup), or estimated on the fly from y when y has no lit texel (and
// at layer 0 with settings.trace_first_bounce). A non-finite sample adds 0 and is counted.
// Random streams: B_0 path_sampler(seed, texel, sample), B_k kBounceRngStreamBase * k + texel.
class BounceLayerEstimator {
 public:
  virtual ~BounceLayerEstimator() = default;
  // `caches[j]` holds B_j for j < pass.layer; `cache_versions[j]` changes whenever caches[j] is rebuilt.
  virtual void estimate(const BounceLayerPass& pass, const std::vector<BounceLayerCache>& caches,
                        const std::vector<uint64_t>& cache_versions) = 0;
  virtual BounceGatherCounts counts() const = 0;
  // Whether the estimator builds the layers' caches itself (the Vulkan backend, on the device):
  // bake_per_bounce then calls build_cache with each layer's per-texel means and validity where it
  // would build a BounceLayerCache on the host (whose `caches` entries then stay empty), at the
  // same points of the schedule.
  virtual bool builds_caches() const { return false; }
  virtual void build_cache(size_t layer, const std::vector<Vec3>& means, const std::vector<uint8_t>& valid) {}
};

// E/pi at every live texel as the sum of the bounce layers B_0..B_K, each kept separately
// (LightmapEstimate::bounces, recorded_bounces = K + 1; they sum to the total), with
// bounce_statistics filled. Under a time budget a layer's texels may hold one sample more than
// others (the partial last pass); every layer of every texel is the mean of its own samples, and
// TexelAccumulator::samples is the texel's B_0 count. Uses spp, time_budget_seconds, budget_clock,
// target_relative_error, max_bounces, seed, safety_bounce_cap, progress and work_share; the
// estimator the rest.
LightmapEstimate bake_per_bounce(const TexelGBuffer& gbuffer, const IntegratorSettings& settings,
                                 BounceLayerEstimator& estimator);

}  // namespace exitance
