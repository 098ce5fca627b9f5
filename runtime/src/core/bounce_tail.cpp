#include "exitance/runtime/core/bounce_tail.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "exitance/common/bounce_gather.h"

namespace exitance {

BounceTail estimate_bounce_tail(const BounceTailInputs& in) {
  BounceTail t;
  const size_t n = in.total.size();
  double area = 0, previous = 0, last = 0, total = 0;
  for (size_t i = 0; i < n; ++i) {
    area += in.area[i];
    previous += in.area[i] * in.previous_bounce[i];
    last += in.area[i] * in.last_bounce[i];
    total += in.area[i] * in.total[i];
  }
  if (!(area > 0) || !(total > 0)) {
    t.below_noise = true;
    return t;
  }
  if (!(last > 0)) {  // nothing bounced further: the tail is exactly 0
    t.below_noise = true;
    return t;
  }
  t.ratio = previous > 0 ? last / previous : std::numeric_limits<double>::infinity();
  const double factor = geometric_tail_factor(float(std::min(t.ratio, 2.0)));
  const double mean_total = total / area;
  const double eps = 1e-3 * mean_total * mean_total;
  double tail2 = 0, noise2 = 0;
  for (size_t i = 0; i < n; ++i) {
    const double w = in.area[i] / (in.total[i] * in.total[i] + eps);
    const double tail = in.last_bounce[i] * factor;
    tail2 += w * (std::isinf(factor) ? (in.last_bounce[i] > 0 ? factor : 0.0) : tail * tail);
    noise2 += w * in.total_variance[i];
  }
  t.tail_rms = std::sqrt(tail2 / area);
  t.noise_rms = std::sqrt(noise2 / area);
  t.below_noise = t.tail_rms <= t.noise_rms;
  return t;
}

}  // namespace exitance
