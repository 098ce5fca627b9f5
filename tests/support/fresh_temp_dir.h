// An empty folder of its own for one test: the system temp folder / exitance-test-NAME-PID, emptied
// first (a crashed earlier run may have left it). The test removes it at the end.
#pragma once
#include <unistd.h>

#include <filesystem>
#include <string>

namespace exitance::testing {

inline std::filesystem::path fresh_temp_dir(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("exitance-test-" + name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace exitance::testing
