#include "exitance/bake/cache/bundle_cache.h"

#include <fstream>
#include <iterator>
#include <map>
#include <system_error>

#include <nlohmann/json.hpp>

#include "exitance/bake/cache/cache_entry_folder.h"
#include "exitance/bake/cache/sha256_stream.h"
#include "exitance/runtime/bundle/bundle_directory.h"

namespace exitance {

namespace fs = std::filesystem;
using json = nlohmann::json;
using cache_entry::discard;
using cache_entry::unique_suffix;

namespace {

constexpr const char* kEntryFile = "entry.json";
constexpr const char* kEntryFormat = "exitance-bundle-cache-entry";
constexpr int kEntryVersion = 1;

// A bundle file as an entry names it: a plain name, or one folder and a plain name (preview/...),
// none starting with '.', so a damaged entry.json cannot point outside the entry.
bool is_plain_bundle_path(const std::string& name) {
  const fs::path path(name);
  if (name.empty() || name == kEntryFile || path.has_root_path()) return false;
  size_t parts = 0;
  for (const fs::path& part : path) {
    const std::string text = part.string();
    if (text.empty() || text[0] == '.') return false;
    ++parts;
  }
  return parts <= 2;
}

// The regular files under a bundle folder, as paths relative to it ("preview/lightmap-0.png").
std::vector<std::string> bundle_files(const fs::path& folder) {
  std::vector<std::string> names;
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(folder))
    if (!e.is_directory()) names.push_back(e.path().lexically_relative(folder).generic_string());
  return names;
}

// The files an entry lists, with their sizes and hashes, or "" and the problem.
std::map<std::string, std::pair<uintmax_t, std::string>> read_entry(const fs::path& folder, const std::string& key,
                                                                     std::vector<std::string>& warnings,
                                                                     std::string& problem) {
  std::map<std::string, std::pair<uintmax_t, std::string>> files;
  std::ifstream in(folder / kEntryFile);
  if (!in) {
    problem = "entry.json is missing";
    return {};
  }
  try {
    const json entry = json::parse(in);
    if (entry.value("format", "") != kEntryFormat || entry.value("version", 0) != kEntryVersion) {
      problem = "entry.json is not a version-1 cache entry";
      return {};
    }
    if (entry.value("key", "") != key) {
      problem = "entry.json names another key";
      return {};
    }
    warnings = entry.at("warnings").get<std::vector<std::string>>();
    for (const auto& [name, file] : entry.at("files").items()) {
      if (!is_plain_bundle_path(name)) {
        problem = "entry.json lists a file name that is not a plain bundle file";
        return {};
      }
      files[name] = {file.at("bytes").get<uintmax_t>(), file.at("sha256").get<std::string>()};
    }
  } catch (const std::exception& e) {
    problem = std::string("entry.json does not parse (") + e.what() + ")";
    return {};
  }
  if (files.count("manifest.json") == 0) problem = "entry.json lists no manifest.json";
  return files;
}

// Every listed file present with its size and hash, and no other file.
bool entry_is_intact(const fs::path& folder, const std::map<std::string, std::pair<uintmax_t, std::string>>& files,
                     std::string& problem) {
  size_t present = 0;
  for (const std::string& name : bundle_files(folder)) {
    if (name == kEntryFile) continue;
    ++present;
    const fs::path path = folder / name;
    auto listed = files.find(name);
    if (listed == files.end() || !fs::is_regular_file(path)) {
      problem = name + " is not listed in entry.json";
      return false;
    }
    if (fs::file_size(path) != listed->second.first) {
      problem = name + " has " + std::to_string(fs::file_size(path)) + " bytes, entry.json says " +
                std::to_string(listed->second.first);
      return false;
    }
    if (sha256_of_file(path.string()) != listed->second.second) {
      problem = name + " does not match its SHA-256";
      return false;
    }
  }
  if (present != files.size()) {
    problem = "files listed in entry.json are missing";
    return false;
  }
  return true;
}

}  // namespace

BundleCache::BundleCache(fs::path directory) : directory_(std::move(directory)) {}

fs::path BundleCache::entry_folder(const std::string& key) const { return directory_ / "v1" / key; }

bool BundleCache::restore(const std::string& key, const fs::path& out,
                          const std::function<std::string(const std::string&)>& edit_manifest,
                          std::vector<std::string>& warnings, Diagnostics& diagnostics) const {
  const fs::path folder = entry_folder(key);
  std::error_code error;
  if (!fs::is_directory(folder, error)) return false;
  std::string problem;
  bool intact = false;
  std::map<std::string, std::pair<uintmax_t, std::string>> files;
  try {
    files = read_entry(folder, key, warnings, problem);
    intact = problem.empty() && entry_is_intact(folder, files, problem);
  } catch (const std::exception& e) {
    problem = e.what();
  }
  std::string manifest;
  if (intact) {
    try {
      std::ifstream in(folder / "manifest.json", std::ios::binary);
      manifest = edit_manifest(std::string(std::istreambuf_iterator<char>(in), {}));
    } catch (const std::exception& e) {
      intact = false;
      problem = std::string("manifest.json: ") + e.what();
    }
  }
  if (!intact) {
    diagnostics.warn("cache " + folder.string() + ": " + problem + "; rebuilding it");
    discard(folder);
    return false;
  }
  write_bundle_atomically(out, [&](const fs::path& dir) {
    for (const auto& [name, file] : files)
      if (name != "manifest.json") {
        fs::create_directories((dir / name).parent_path());
        fs::copy_file(folder / name, dir / name);
      }
    std::ofstream file(dir / "manifest.json", std::ios::binary);
    file << manifest;
    if (!file) throw std::runtime_error("cannot write " + (dir / "manifest.json").string());
  });
  return true;
}

void BundleCache::store(const std::string& key, const fs::path& bundle, const std::vector<std::string>& warnings,
                        Diagnostics& diagnostics) const {
  const fs::path folder = entry_folder(key);
  const fs::path staging = folder.parent_path() / (".staging-" + key + "-" + unique_suffix());
  try {
    fs::create_directories(staging);
    json entry = {{"format", kEntryFormat}, {"version", kEntryVersion}, {"key", key},
                  {"warnings", warnings},   {"files", json::object()}};
    for (const std::string& name : bundle_files(bundle)) {  // the preview/ folder too
      if (!fs::is_regular_file(bundle / name)) continue;
      fs::create_directories((staging / name).parent_path());
      fs::copy_file(bundle / name, staging / name);
      entry["files"][name] = {{"bytes", fs::file_size(staging / name)}, {"sha256", sha256_of_file((staging / name).string())}};
    }
    {
      std::ofstream out(staging / kEntryFile);
      out << entry.dump(1) << "\n";
      if (!out) throw std::runtime_error("cannot write " + (staging / kEntryFile).string());
    }
    cache_entry::publish(staging, folder);  // another bake that stored this key first keeps its entry
  } catch (const std::exception& e) {
    std::error_code ignored;
    fs::remove_all(staging, ignored);
    diagnostics.warn("cache " + directory_.string() + ": could not store this bake (" + std::string(e.what()) + ")");
  }
}

}  // namespace exitance
