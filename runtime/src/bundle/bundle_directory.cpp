#include "exitance/runtime/bundle/bundle_directory.h"

#include <unistd.h>

#include <stdexcept>

namespace exitance {

namespace fs = std::filesystem;

void write_bundle_atomically(const fs::path& out_dir, const std::function<void(const fs::path&)>& write_contents) {
  const fs::path target = fs::absolute(out_dir).lexically_normal();
  const std::string suffix = std::to_string(::getpid());
  const fs::path temporary = target.parent_path() / (target.filename().string() + ".tmp-" + suffix);
  const fs::path previous = target.parent_path() / (target.filename().string() + ".old-" + suffix);
  std::error_code ec;
  fs::create_directories(target.parent_path(), ec);
  fs::remove_all(temporary, ec);
  if (!fs::create_directory(temporary, ec))
    throw std::runtime_error("cannot create " + temporary.string() + ": " + ec.message());
  try {
    write_contents(temporary);
    if (fs::exists(target)) fs::rename(target, previous);
    fs::rename(temporary, target);
    fs::remove_all(previous, ec);
  } catch (...) {
    fs::remove_all(temporary, ec);
    if (!fs::exists(target) && fs::exists(previous)) fs::rename(previous, target, ec);
    throw;
  }
}

}  // namespace exitance
