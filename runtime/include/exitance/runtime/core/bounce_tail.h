// When the per-bounce mode (IntegratorMode::Bounces) has run enough bounces: when the bounces not
// run, extrapolated geometrically from the ratio of the last two (bounce_gather.h,
// geometric_tail_factor), are below the noise of the total - not when the last bounce is small
// (at albedo 0.99 the tail is ~100x the last bounce). Backend-neutral: per-texel inputs in, one
// decision out.
#pragma once
#include <vector>

namespace exitance {

// Per live texel, luminances of E/pi.
struct BounceTailInputs {
  std::vector<double> area;                      // weight of the texel (world texel size squared)
  std::vector<double> previous_bounce;           // B_{k-1}
  std::vector<double> last_bounce;               // B_k
  std::vector<double> previous_bounce_variance;  // variance of the mean of B_{k-1} (empty: 0)
  std::vector<double> last_bounce_variance;      // variance of the mean of B_k (empty: 0)
  std::vector<double> total;                     // B_0 + ... + B_k
  std::vector<double> total_variance;            // variance of the mean of the total
};

struct BounceTail {
  double ratio = 0;       // r: relative RMS of B_k over that of B_{k-1}
  double tail_rms = 0;    // relative RMS of the extrapolated tail, B_k r / (1 - r)
  double noise_rms = 0;   // relative RMS of the total's standard error
  bool below_noise = false;  // tail_rms <= kTailToNoise * noise_rms: further bounces would change less than the noise
};

// The stop is at half the noise, not at the noise: at the stop the truncation's bias^2 then adds at
// most 1/4 of the variance to the relMSE (at the noise itself it could double it, and halving a
// relMSE takes twice the samples in every pass, while one more bounce costs one pass). On the
// sunlit courtyard at 32 spp, stopping at the noise left one bounce and a truncation bias of
// relMSE 0.006 against a variance of 0.007 (bench/results/per-bounce.md).
constexpr double kTailToNoise = 0.5;

// Relative RMS: sqrt(sum_i a_i x_i^2 / (total_i^2 + eps) / sum_i a_i), eps = 1e-3 x (area-weighted
// mean total)^2: the relMSE the benchmarks use (bias^2 of the truncation against the variance),
// scale free. The ratio is measured in that same norm, so it follows the texels that dominate it:
// where the total is small (shadows lit by bounces) the bounces decay more slowly than the scene's
// mean says (a scene-mean ratio of B_1/B_0 stopped the sunlit courtyard after one bounce with a
// truncation bias of relMSE 0.006). Each B^2 has its variance subtracted (E[x^2] = mean^2 + var),
// so noise alone does not look like light that keeps bouncing. r >= 1 gives an infinite tail. An
// empty or black scene, or a last bounce of 0, is below the noise.
BounceTail estimate_bounce_tail(const BounceTailInputs& inputs);

}  // namespace exitance
