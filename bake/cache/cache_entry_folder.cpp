#include "exitance/bake/cache/cache_entry_folder.h"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <random>
#include <system_error>

namespace exitance::cache_entry {

namespace fs = std::filesystem;

std::string unique_suffix() {
  static std::atomic<uint64_t> counter{0};
  std::random_device random;
  return std::to_string(::getpid()) + "-" +
         std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + "-" +
         std::to_string(random()) + "-" + std::to_string(counter++);
}

void discard(const fs::path& folder) {
  std::error_code error;
  const fs::path trash = folder.parent_path() / (".discard-" + unique_suffix());
  fs::rename(folder, trash, error);
  fs::remove_all(error ? folder : trash, error);
}

void publish(const fs::path& staging, const fs::path& folder) {
  std::error_code error;
  fs::rename(staging, folder, error);
  if (error) fs::remove_all(staging, error);
}

}  // namespace exitance::cache_entry
