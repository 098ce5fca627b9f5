// A stage's progress callback called at most every 1 % of its work, from the calling thread (UV
// generation's flattening and packing report through it).
#pragma once
#include <functional>

namespace exitance::uvgen {

class ProgressSteps {
 public:
  explicit ProgressSteps(const std::function<void(double)>& report) : report_(report) {}
  void at(double fraction) {
    if (report_ && fraction >= last_ + 0.01) {
      last_ = fraction;
      report_(fraction);
    }
  }

 private:
  const std::function<void(double)>& report_;
  double last_ = -1;
};

}  // namespace exitance::uvgen
