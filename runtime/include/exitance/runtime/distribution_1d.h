// Piecewise-constant 1D distribution: sampling proportional to non-negative weights.
#pragma once
#include <algorithm>
#include <cstddef>
#include <vector>

#include "exitance/common/distribution.h"

namespace exitance {

class Distribution1D {
 public:
  Distribution1D() = default;
  explicit Distribution1D(const std::vector<double>& weights) {
    cdf_.resize(weights.size() + 1, 0.0);
    for (size_t i = 0; i < weights.size(); ++i) cdf_[i + 1] = cdf_[i] + std::max(0.0, weights[i]);
    total_ = cdf_.back();
    if (total_ > 0)
      for (double& c : cdf_) c /= total_;
  }
  bool empty() const { return !(total_ > 0); }
  size_t size() const { return cdf_.empty() ? 0 : cdf_.size() - 1; }
  double total() const { return total_; }
  float pmf(size_t i) const { return float(cdf_[i + 1] - cdf_[i]); }
  // Normalised CDF, size() + 1 entries (all zero when every weight is zero).
  const std::vector<double>& cdf() const { return cdf_; }

  // Returns the chosen index; `remapped` is u rescaled to [0,1) inside the chosen cell.
  size_t sample(float u, float* remapped = nullptr) const {
    float probability = 0;
    const size_t i = sample_cdf(cdf_.data(), uint32_t(size()), u, probability);  // shared with the shaders
    if (remapped) *remapped = cdf_remap(cdf_.data(), uint32_t(i), u);
    return i;
  }

 private:
  std::vector<double> cdf_;
  double total_ = 0;
};

}  // namespace exitance
