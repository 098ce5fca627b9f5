// What every cache entry (a whole bundle, bundle_cache.h; one stage's products, stage_cache.h) is
// written and thrown away with: a staging name no other process uses at the same time, and the
// removal of a damaged entry by renaming it out of the way first.
#pragma once
#include <filesystem>
#include <string>

namespace exitance::cache_entry {

// A name no other process uses at the same time: pid, time and a random number.
std::string unique_suffix();

// Moves a damaged entry out of the way (a rename, so a concurrent reader sees it whole or not at
// all), then deletes it.
void discard(const std::filesystem::path& folder);

// Renames the finished `staging` folder to `folder`; when another bake stored it first (the rename
// fails), theirs stays and `staging` is removed.
void publish(const std::filesystem::path& staging, const std::filesystem::path& folder);

}  // namespace exitance::cache_entry
