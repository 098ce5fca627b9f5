#include "exitance/runtime/core/bounce_tail.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "exitance/common/bounce_gather.h"

namespace exitance {

BounceTail estimate_bounce_tail(const BounceTailInputs& in) {
  BounceTail t;
  const size_t n = in.total.size();
  auto variance = [](const std::vector<double>& v, size_t i) { return v.empty() ? 0.0 : v[i]; };
  double area = 0, total = 0;
  for (size_t i = 0; i < n; ++i) {
    area += in.area[i];
    total += in.area[i] * in.total[i];
  }
  if (!(area > 0) || !(total > 0)) {
    t.below_noise = true;
    return t;
  }
  const double mean_total = total / area;
  const double eps = 1e-3 * mean_total * mean_total;
  double previous2 = 0, last2 = 0, noise2 = 0;
  for (size_t i = 0; i < n; ++i) {
    const double w = in.area[i] / (in.total[i] * in.total[i] + eps);
    previous2 += w * std::max(0.0, in.previous_bounce[i] * in.previous_bounce[i] - variance(in.previous_bounce_variance, i));
    last2 += w * std::max(0.0, in.last_bounce[i] * in.last_bounce[i] - variance(in.last_bounce_variance, i));
    noise2 += w * in.total_variance[i];
  }
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
