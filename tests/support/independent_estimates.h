// Mean and standard error of independent estimates of one quantity (repeats with different seeds,
// probe copies, separate probes or voxels): the sample variance over n - 1, divided by n.
#pragma once
#include <cmath>
#include <cstddef>
#include <vector>

namespace exitance::testing {

struct MeanAndError {
  double mean = 0, standard_error = 0;
  size_t count = 0;
};

inline MeanAndError mean_and_standard_error(const std::vector<double>& values) {
  MeanAndError m;
  m.count = values.size();
  if (values.empty()) return m;
  for (double v : values) m.mean += v / double(values.size());
  if (values.size() < 2) return m;
  double variance = 0;
  for (double v : values) variance += (v - m.mean) * (v - m.mean) / double(values.size() - 1);
  m.standard_error = std::sqrt(variance / double(values.size()));
  return m;
}

// runs[k][i]: run k's estimate of item i (a texel). The mean over items with a positive mean of
// each item's variance across runs relative to its squared mean (equal-sample variance ratios).
inline double mean_relative_variance(const std::vector<std::vector<double>>& runs) {
  double sum = 0;
  size_t counted = 0;
  for (size_t i = 0; i < runs.front().size(); ++i) {
    std::vector<double> values;
    for (const auto& run : runs) values.push_back(run[i]);
    const MeanAndError m = mean_and_standard_error(values);
    if (!(m.mean > 0)) continue;
    sum += m.standard_error * m.standard_error * double(values.size()) / (m.mean * m.mean);
    ++counted;
  }
  return sum / double(counted);  // NaN when no item has light: a ratio of it fails every bound
}

}  // namespace exitance::testing
