// A one-line progress bar on stderr, drawn only when stderr is a terminal.
#pragma once
#include <chrono>
#include <cstdint>
#include <string>

namespace exitance {

class ProgressBar {
 public:
  ProgressBar();
  void update(const std::string& stage, double fraction, uint64_t rays);
  void finish();
  // The stage of the last update, drawn or not ("start" before any): what a failure names.
  const std::string& stage() const { return stage_; }

 private:
  bool enabled_ = false;
  bool drawn_ = false;
  std::string stage_ = "start";
  std::chrono::steady_clock::time_point stage_start_;
};

}  // namespace exitance
