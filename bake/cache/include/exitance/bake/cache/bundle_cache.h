// A content-addressed cache of whole bundles (issue 12, "skip what a scene does not need"): a bake
// whose key (bake_cache_key.h) is in the cache copies the stored bundle instead of running any
// stage after the import.
//
// Layout: DIR/v1/<key>/ holds the bundle's files and entry.json (every file's size and SHA-256).
// An entry is written into a temporary sibling and renamed into place, so a reader never sees a
// partial entry and two bakes storing the same key at once are safe (the second rename loses and
// its copy is removed). A restore re-hashes every file: a damaged, truncated or foreign entry is
// reported with a warning, removed, and the bake runs as if it were absent. Nothing is evicted:
// delete DIR to reclaim the space.
#pragma once
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "exitance/bake/diagnostics.h"

namespace exitance {

class BundleCache {
 public:
  explicit BundleCache(std::filesystem::path directory);

  // Copies the entry for `key` into `out` (atomically, as a bake writes), its manifest.json passed
  // through `edit_manifest` (which may throw to refuse the entry), sets `warnings` to those the
  // stored bake gave, and returns true; false when there is no usable entry (a damaged one is
  // warned about and removed).
  bool restore(const std::string& key, const std::filesystem::path& out,
               const std::function<std::string(const std::string&)>& edit_manifest, std::vector<std::string>& warnings,
               Diagnostics& diagnostics) const;

  // Stores the bundle folder `bundle` under `key`, with the warnings its bake gave (a restore
  // repeats them). A failure to store is a warning, never an error: the bake itself succeeded.
  void store(const std::string& key, const std::filesystem::path& bundle, const std::vector<std::string>& warnings,
             Diagnostics& diagnostics) const;

  std::filesystem::path entry_folder(const std::string& key) const;

 private:
  std::filesystem::path directory_;
};

}  // namespace exitance
