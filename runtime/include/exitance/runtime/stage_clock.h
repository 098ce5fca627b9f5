// Wall-clock seconds per stage of a run, for its report: lap() returns the time since the last lap
// (or since construction) and starts the next stage.
#pragma once
#include <chrono>

namespace exitance {

class StageClock {
 public:
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return seconds;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace exitance
