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
  std::vector<double> area;             // weight of the texel (world texel size squared)
  std::vector<double> previous_bounce;  // B_{k-1}
  std::vector<double> last_bounce;      // B_k
  std::vector<double> total;            // B_0 + ... + B_k
  std::vector<double> total_variance;   // variance of the mean of the total
};

struct BounceTail {
  double ratio = 0;       // r = area-weighted mean of B_k / that of B_{k-1}
  double tail_rms = 0;    // sqrt(mean over texels of (B_k r / (1 - r))^2 / (total^2 + eps)), area-weighted
  double noise_rms = 0;   // sqrt(mean over texels of total_variance / (total^2 + eps)), area-weighted
  bool below_noise = false;  // tail_rms <= noise_rms: a further bounce would change less than the noise
};

// The relative weights 1 / (total^2 + eps), eps = 1e-3 x (mean total)^2, make the comparison the
// relMSE the benchmarks use (bias^2 of the truncation against the variance), and scale free.
// r >= 1 (no decay yet) gives an infinite tail. An empty or black scene is below the noise.
BounceTail estimate_bounce_tail(const BounceTailInputs& inputs);

}  // namespace exitance
