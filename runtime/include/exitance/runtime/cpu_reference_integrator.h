// The CPU reference: an unbiased, deliberately simple path tracer of incident irradiance
// (stored as E/pi) at lightmap texels, on Embree. Every faster backend is checked against it.
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "exitance/runtime/scene.h"
#include "exitance/runtime/texel_gbuffer.h"

namespace exitance {

struct IntegratorSettings {
  uint32_t spp = 128;              // samples per texel; 0 = until the time budget ends
  double time_budget_seconds = 0;  // 0 = no budget
  double target_relative_error = 0;  // stop a texel when its relative standard error is below this; 0 = off
  int max_bounces = -1;            // diffuse bounces after the first hit; -1 = until Russian roulette
  uint64_t seed = 0;
  int recorded_bounces = 4;        // layers bounce0 (= direct) .. bounce<K-1> kept separately
  int russian_roulette_start = 3;  // first bounce at which roulette may end a path
  int safety_bounce_cap = 4096;    // never reached by paths of albedo < 0.998 in practice; documented
  std::function<void(double fraction_done, uint64_t rays)> progress;  // called between passes
};

// Sums of per-sample estimates of E/pi (RGB, doubles so long runs keep precision).
struct TexelAccumulator {
  double total[3] = {0, 0, 0};
  double total_squared[3] = {0, 0, 0};
  double direct[3] = {0, 0, 0};
  uint32_t samples = 0;
};

struct LightmapEstimate {
  std::vector<TexelAccumulator> texels;
  std::vector<double> bounces;  // [bounce][texel][rgb] flattened: (k * texel_count + i) * 3 + c
  int recorded_bounces = 0;
  uint64_t rays = 0;
  double seconds = 0;
  uint64_t nonfinite_samples = 0;  // samples discarded because they were NaN/Inf (should stay 0)

  Vec3 mean_total(size_t texel) const;
  Vec3 mean_direct(size_t texel) const;
  Vec3 mean_bounce(int bounce, size_t texel) const;
  // Variance of the mean (standard error squared) of the total, per channel.
  Vec3 variance_of_mean(size_t texel) const;
};

// Irradiance (as E/pi) estimator at an arbitrary surface point; exposed so probes and tests reuse it.
struct SurfacePoint {
  Vec3 position;
  Vec3 geometric_normal;
  Vec3 shading_normal;
};

class CpuReferenceIntegrator {
 public:
  CpuReferenceIntegrator(const Scene& scene);
  ~CpuReferenceIntegrator();
  LightmapEstimate bake(const TexelGBuffer& gbuffer, const IntegratorSettings& settings) const;

 private:
  struct Impl;
  Impl* impl_;
};

}  // namespace exitance
