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

}  // namespace exitance::testing
