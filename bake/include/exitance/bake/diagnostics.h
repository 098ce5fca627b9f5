// Warnings collected while importing and laying out a scene. The bake command prints them
// as "bake: warning: ..." lines; tests inspect them directly.
#pragma once
#include <string>
#include <vector>

namespace exitance {

struct Diagnostics {
  std::vector<std::string> warnings;
  void warn(std::string message) { warnings.push_back(std::move(message)); }
};

}  // namespace exitance
