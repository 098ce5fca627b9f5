// The per-stage cache (issue 12, "Skip"): one offline stage's products under the key of exactly
// the inputs it reads (stage_cache_keys.h), so a bake whose light changed reuses the layout, the
// G-buffer, the sealed texels, the octree and the probe positions of the bake before it.
//
// Layout: DIR/v1/stages/<stage>/<key>/ holds the stage's files (as its products' codecs write them)
// and entry.json (the stage, the key, the warnings the stage gave, every file's size and SHA-256).
// Written and checked like a bundle entry (bundle_cache.h): staged in a temporary sibling and
// renamed into place; every file re-hashed on restore, and a damaged, truncated or foreign entry is
// warned about, removed and computed again.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "exitance/bake/diagnostics.h"

namespace exitance {

struct StageEntry {
  std::map<std::string, std::vector<uint8_t>> files;  // plain file names -> bytes
  std::vector<std::string> warnings;                  // what the stage warned about when it ran
};

class StageCache {
 public:
  explicit StageCache(std::filesystem::path directory);

  // The intact entry, or nullopt when there is none (a damaged one is warned about and removed).
  std::optional<StageEntry> restore(const std::string& stage, const std::string& key, Diagnostics& diagnostics) const;

  // A failure to store is a warning, never an error.
  void store(const std::string& stage, const std::string& key, const StageEntry& entry, Diagnostics& diagnostics) const;

  // For an entry that verified but whose contents the stage's decoder refused: warned about, removed.
  void reject(const std::string& stage, const std::string& key, const std::string& problem,
              Diagnostics& diagnostics) const;

  std::filesystem::path entry_folder(const std::string& stage, const std::string& key) const;

 private:
  std::filesystem::path directory_;
};

}  // namespace exitance
