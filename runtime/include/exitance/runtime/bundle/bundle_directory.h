// Writes the output bundle atomically: everything goes to a sibling temporary folder that is
// renamed over OUT at the end, so a failed or interrupted run leaves an earlier bundle intact.
#pragma once
#include <filesystem>
#include <functional>
#include <string>

namespace exitance {

// `write_contents(temporary_dir)` fills the folder; on any exception the folder is removed and
// the exception propagates. Throws std::runtime_error on filesystem failure.
void write_bundle_atomically(const std::filesystem::path& out_dir,
                             const std::function<void(const std::filesystem::path&)>& write_contents);

}  // namespace exitance
