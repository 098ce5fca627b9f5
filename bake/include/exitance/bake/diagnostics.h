// Warnings collected during a bake (import repairs, layout, scene checks, the backend choice,
// discarded samples). The bake command prints them as "bake: warning: ..." lines after the run;
// tests inspect them directly.
#pragma once
#include <string>
#include <vector>

namespace exitance {

struct Diagnostics {
  std::vector<std::string> warnings;
  void warn(std::string message) { warnings.push_back(std::move(message)); }
};

}  // namespace exitance
