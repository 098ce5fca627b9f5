#include "exitance/runtime/core/bounce_tail.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "exitance/common/bounce_gather.h"
#include "exitance/runtime/core/parallel_chunks.h"

namespace exitance {

namespace {

// The reductions run in blocks of this many texels on all cores, each block's partial sums added in
// block order: the same sums on every machine whatever its core count (serially they were two
// passes over seven arrays of a million texels on one core, after the inputs were made on all).
constexpr size_t kBlockTexels = 32768;

// N sums over texels [0, n): term(i, sums) adds texel i's terms. One block (n <= kBlockTexels) sums
// in texel order, as a serial loop does.
template <size_t N, typename Term>
std::array<double, N> block_sums(size_t n, const Term& term) {
  const size_t blocks = (n + kBlockTexels - 1) / kBlockTexels;
  std::vector<std::array<double, N>> partial(blocks);
  for_each_chunk(blocks, [&](size_t first, size_t last) {
    for (size_t b = first; b < last; ++b) {
      std::array<double, N> sums{};
      for (size_t i = b * kBlockTexels, end = std::min(n, i + kBlockTexels); i < end; ++i) term(i, sums);
      partial[b] = sums;
    }
  }, 1);
  std::array<double, N> total{};
  for (const std::array<double, N>& sums : partial)
    for (size_t k = 0; k < N; ++k) total[k] += sums[k];
  return total;
}

}  // namespace

BounceTail estimate_bounce_tail(const BounceTailInputs& in) {
  BounceTail t;
  const size_t n = in.total.size();
  auto variance = [](const std::vector<double>& v, size_t i) { return v.empty() ? 0.0 : v[i]; };
  const auto [area, total] = block_sums<2>(n, [&](size_t i, std::array<double, 2>& sums) {
    sums[0] += in.area[i];
    sums[1] += in.area[i] * in.total[i];
  });
  if (!(area > 0) || !(total > 0)) {
    t.below_noise = true;
    return t;
  }
  const double mean_total = total / area;
  const double eps = 1e-3 * mean_total * mean_total;
  const auto [previous2, last2, noise2] = block_sums<3>(n, [&](size_t i, std::array<double, 3>& sums) {
    const double w = in.area[i] / (in.total[i] * in.total[i] + eps);
    sums[0] += w * std::max(0.0, in.previous_bounce[i] * in.previous_bounce[i] - variance(in.previous_bounce_variance, i));
    sums[1] += w * std::max(0.0, in.last_bounce[i] * in.last_bounce[i] - variance(in.last_bounce_variance, i));
    sums[2] += w * in.total_variance[i];
  });
  t.noise_rms = std::sqrt(noise2 / area);
  if (!(last2 > 0)) {  // nothing (above its noise) bounced further: the tail is 0
    t.below_noise = true;
    return t;
  }
  t.ratio = previous2 > 0 ? std::sqrt(last2 / previous2) : std::numeric_limits<double>::infinity();
  const double factor = geometric_tail_factor(float(std::min(t.ratio, 2.0)));
  t.tail_rms = std::sqrt(last2 / area) * factor;
  t.below_noise = t.tail_rms <= kTailToNoise * t.noise_rms;
  return t;
}

}  // namespace exitance
