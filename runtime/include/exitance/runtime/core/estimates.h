// What integrators return: sums of per-sample estimates, from which means and standard errors follow.
// Every backend fills the same types, so tests compare them directly.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "exitance/common/gpu_layout.h"
#include "exitance/runtime/core/guiding_choice.h"
#include "exitance/runtime/spherical_harmonics.h"
#include "exitance/runtime/vec_math.h"

namespace exitance {

// The error floor of relative errors, as a fraction of the scene's mean E/pi: SE / (mean + floor)
// keeps dark texels from dominating (the adaptive plan, the error layer and stats.error use it).
// 1 %: on the sample scenes about the bench's relMSE regularizer (r^2 + 1e-3), and the adaptive plan's
// best of 1 % and 5 % there (bench/results/adaptive-sampling.md).
constexpr double kErrorFloorFraction = 0.01;

struct TexelAccumulator {
  double total[3] = {0, 0, 0};
  double total_squared[3] = {0, 0, 0};
  double direct[3] = {0, 0, 0};
  uint32_t samples = 0;
};

// What the per-bounce mode (IntegratorMode::Bounces) did; all zero in path mode.
struct BounceGatherStatistics {
  int bounces = 0;                 // indirect passes run: layers B_0 .. B_bounces
  std::vector<uint32_t> samples;   // per layer, samples every texel has (a time budget can leave later layers behind)
  // Per layer, the texels with one sample more than `samples` (the partial last pass of a time
  // budget, core/partial_layer_pass.h); 0 elsewhere.
  std::vector<uint64_t> texels_with_one_more;
  uint64_t gathers = 0;            // gather rays that hit a surface
  uint64_t texelless_hits = 0;     // of those, hits with no lit texel to read (estimated on the fly instead)
  uint64_t back_face_hits = 0;     // of those, back faces of single-sided surfaces (0, as in path mode)
  double ratio = 0;                // B_k / B_{k-1} of the last two layers (relative RMS, bounce_tail.h)
  double tail_rms = 0;             // the extrapolated tail at the stop, relative RMS (bounce_tail.h)
  double noise_rms = 0;            // the total's noise at the stop, relative RMS
  bool tail_below_noise = false;   // false: stopped by --bounces, the time budget or the layer cap
  bool tail_completed = false;     // the geometric tail B_k r / (1 - r) was added to the last layer
  // Wall-clock seconds of the host loop's parts (core/per_bounce_bake.cpp): the estimator's layer
  // passes (on the GPU: the device's batches and the sums' read-back), the caches' builds, the tail
  // estimates and the stop tests, and the assembly of the result after the loop.
  struct Seconds {
    double passes = 0, caches = 0, tail = 0, assembly = 0;
  } seconds;
};

// Sums over `samples` samples (at least 2) whose mean is `mean` and whose variance of the mean is
// `variance_of_mean`, per channel: total = n mean, total_squared = n mean^2 + n (n - 1) V, so
// LightmapEstimate::mean_total and variance_of_mean give them back (a composite estimate: the
// runtime's base + change, a filtered texel). The direct sums are left alone.
void set_total_sums(TexelAccumulator& texel, uint32_t samples, const double mean[3], const double variance_of_mean[3]);

struct LightmapEstimate {
  std::vector<TexelAccumulator> texels;
  std::vector<double> bounces;  // [bounce][texel][rgb] flattened: (k * texel_count + i) * 3 + c
  int recorded_bounces = 0;
  // Light layers (IntegratorSettings::light_layers; exitance/common/light_layers.h): per layer the
  // sums of E/pi of that light alone, [layer][texel][rgb] as `bounces`; they add up to the total.
  int light_layers = 0;
  std::vector<double> light_sums;
  uint64_t rays = 0;
  double seconds = 0;
  uint64_t nonfinite_samples = 0;  // samples discarded because they were NaN/Inf (should stay 0)
  BounceGatherStatistics bounce_statistics;
  uint64_t guided_vertices = 0;  // path vertices that sampled a guided mixture (--guiding); 0 unguided
  // Light subpaths (IntegratorSettings::light_subpaths): traced, and their vertices kept in pools.
  uint64_t light_subpaths = 0;
  uint64_t light_subpath_vertices = 0;
  uint64_t pilot_samples_dropped = 0;  // --guiding auto: by texels that began to connect after its pilot
  // GuidingMode::Auto: what the choice measured and kept per region (core/guiding_choice.h); empty
  // otherwise or when the bake ended before the pilot did (then every sample tossed its coin).
  bool guiding_auto = false;
  bool guiding_auto_light_subpaths = false;  // what it measured against unguided: light subpaths (else grid guiding)
  // Vulkan: no candidate fits the bake (light subpaths need kLightSubpathPilots pilots and a light
  // that starts them; grid guiding is measured there only where named), so nothing was measured.
  bool guiding_auto_unmeasured = false;
  uint32_t guiding_auto_pilot = 0;  // samples per texel before the choice
  double guiding_auto_cost_factor = 1;  // GuidingChoice::guided_cost_factor (Vulkan's connected samples)
  // Light subpaths under a time budget: the samples per texel at which the pilot was abandoned
  // unmeasured (the pass rate promised too few samples for it to pay); 0: it was not.
  uint32_t guiding_auto_abandoned_at = 0;
  // Host seconds the bake spent setting the choice up before its first pass (the guide, the regions,
  // the strategy words, the pools and their uploads): inside the timed bake, so a short --time feels it.
  double guiding_auto_setup_seconds = 0;
  std::vector<RegionChoice> guiding_regions;
  EfficiencyEvidence guiding_scene;  // the whole scene's evidence, which regions without their own follow
  // Emitter guiding (core/emitter_guiding_cache.h): what the cache held at the end of the bake;
  // records = 0 when it was off or the scene has fewer than two lights of either kind.
  struct EmitterGuidingReport {
    uint32_t records = 0;
    uint32_t records_sampling_learned = 0;  // sampling a learned distribution (area or punctual)
    uint32_t patches = 0;
    uint32_t punctual_lights = 0;
    uint64_t memory_bytes = 0;
    bool dropped = false;  // no record gained enough after the learning samples: the default from there on
    // Vulkan backend's path tracing (0 elsewhere): the host's seconds making the cache and putting
    // it on the device, and folding the device's learning into it between passes (folds of them).
    double setup_seconds = 0, fold_seconds = 0;
    uint32_t folds = 0;
  } emitter_guiding;
  bool adaptive = false;         // samples were planned per texel (core/adaptive_sampling_plan.h)
  uint32_t adaptive_pilot = 0;   // samples per texel of the pilot before the plan (0: no plan made)
  // DirectionalMode::Sh1: per texel the sums of the L1 estimates (path.h sh1_direction_factor),
  // [texel][axis x,y,z][rgb] flattened: (i * 3 + axis) * 3 + c; empty otherwise.
  std::vector<double> sh1;

  Vec3 mean_total(size_t texel) const;
  Vec3 mean_direct(size_t texel) const;
  Vec3 mean_bounce(int bounce, size_t texel) const;
  // The L1 coefficient along world axis `axis` (0 x, 1 y, 2 z), RGB; 0 without sh1 sums.
  Vec3 mean_sh1(int axis, size_t texel) const;
  bool has_sh1() const { return !sh1.empty(); }
  // Variance of the mean (standard error squared) of the total, per channel.
  Vec3 variance_of_mean(size_t texel) const;
  // The target-error stopping test of the Vulkan and per-bounce backends (a stopping rule on a texel's
  // own estimate, slightly biased; CPU path tracing plans its samples instead): relative standard
  // error of the luminance below `target`; a texel black with no variance after 16 samples counts as met.
  bool relative_error_below(size_t texel, double target) const;
  // Mean over texels with signal of the relative standard error of the luminance (the manifest's
  // stats.estimated_relative_error).
  double mean_relative_standard_error() const;
  // kErrorFloorFraction times the mean over sampled texels of the luminance of E/pi.
  double error_floor() const;
  // Standard error of the luminance over (its mean + floor): the EXR's error layer.
  float relative_standard_error(size_t texel, double floor) const;
};


// Light probes: per probe, `spp` rays in uniform sphere directions, stratified in sets of
// kProbeStratifiedSetSize consecutive samples (path.h probe_ray_direction; random numbers
// path_sampler(seed, kProbeRngStreamBase + probe, s), its first 2-D draw). Each ray's incident
// radiance L(w) is: the sky on a miss; on a front face (or a double-sided one) Le at the hit, at full
// weight (a probe is no surface: there is no next-event estimation at it, so nothing to MIS with),
// plus albedo times one path sample of E/pi at the hit, exactly the lightmap texel estimator started
// there (same bounce limits, counted from the hit); 0 on the back face of a single-sided surface.
// Projected to L2 SH with weight 4*pi/spp.

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
  // Per probe, Vulkan runs only (empty elsewhere): sum over samples of (L_c(w) * Y_0 * 4pi)^2, the
  // squares of each sample's L0 term, for the probe's error estimate (l0_variance_of_mean).
  std::vector<std::array<double, 3>> l0_square_sum;
  // The runtime's refreshed probes with light layers (vulkan/probe_refresh.h; docs/runtime.md
  // "Probes"): per layer and probe, sh_sum's part from that light, at [layer * probes + probe]; the
  // layers sum to sh_sum. Empty when light_layers is 0.
  int light_layers = 0;
  std::vector<std::array<double, 27>> light_sh_sum;
  uint64_t light_subpaths = 0;  // traced for the probes' connections (IntegratorSettings::light_subpaths)
  uint64_t rays = 0;
  double seconds = 0;
  uint64_t nonfinite_samples = 0;

  ShRgb mean(size_t probe) const;  // SH coefficients of incident radiance
  // The variance of the mean of L0 summed over rgb, as variance_of_mean_from_sums (publishing_rule.h);
  // 0 without l0_square_sum or below 2 samples.
  double l0_variance_of_mean(size_t probe) const;
  Vec3 mean_axis_irradiance_over_pi(size_t probe, int axis) const;  // axis 0..5 as above; 0 when absent
};

}  // namespace exitance
