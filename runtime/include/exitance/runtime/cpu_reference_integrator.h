// The CPU reference: an unbiased, deliberately simple path tracer of incident irradiance
// (stored as E/pi) at lightmap texels, on Embree. Every faster backend is checked against it.
#pragma once
#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "exitance/runtime/scene.h"
#include "exitance/runtime/spherical_harmonics.h"
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

// Light probes: per probe, `spp` rays in uniform sphere directions, stratified in sets of
// kProbeStratifiedSetSize consecutive samples (sample s of a set starting at b with n samples uses
// probe_direction(s - b, n, u1, u2) from sampling.h; n = min(set size, spp - b)); random numbers
// Pcg32(seed, kProbeRngStreamBase + probe, s), u1 then u2 drawn first. Each ray's incident
// radiance L(w) is: the sky on a miss; on a front face (or a double-sided one) Le at the hit, at full
// weight (a probe is no surface: there is no next-event estimation at it, so nothing to MIS with),
// plus albedo times one path sample of E/pi at the hit, exactly the lightmap texel estimator started
// there (same bounce limits, counted from the hit); 0 on the back face of a single-sided surface.
// Projected to L2 SH with weight 4*pi/spp.
constexpr uint64_t kProbeRngStreamBase = 1ull << 40;
constexpr uint32_t kProbeStratifiedSetSize = 256;

struct ProbeEstimate {
  // Per probe: sum over samples of L(w) * Y_i(w) * 4pi at [i * 3 + c] (divide by samples).
  std::vector<std::array<double, 27>> sh_sum;
  // Per probe, CPU reference only (empty elsewhere): sum over samples of L(w) * max(0, w . a) * 4
  // for the six axes a = +x, -x, +y, -y, +z, -z at [axis * 3 + c]; divided by samples it is an
  // unbiased E/pi for those normals (an ambient cube), free of SH truncation, which tests use to
  // check the probe radiance itself and to measure the L2 approximation.
  std::vector<std::array<double, 18>> axis_irradiance_sum;
  std::vector<uint32_t> samples;         // per probe
  std::vector<uint32_t> backface_hits;   // per probe: rays that hit the back of a single-sided surface
  uint64_t rays = 0;
  double seconds = 0;
  uint64_t nonfinite_samples = 0;

  ShRgb mean(size_t probe) const;  // SH coefficients of incident radiance
  Vec3 mean_axis_irradiance_over_pi(size_t probe, int axis) const;  // axis 0..5 as above; 0 when absent
};

class CpuReferenceIntegrator {
 public:
  CpuReferenceIntegrator(const Scene& scene);
  ~CpuReferenceIntegrator();
  LightmapEstimate bake(const TexelGBuffer& gbuffer, const IntegratorSettings& settings) const;
  // Uses spp (0 needs a time budget), time_budget_seconds, max_bounces, seed, russian_roulette_start,
  // safety_bounce_cap, progress; probes are independent of the lightmap bake.
  ProbeEstimate bake_probes(const std::vector<Vec3>& positions, const IntegratorSettings& settings) const;

 private:
  struct Impl;
  Impl* impl_;
};

}  // namespace exitance
