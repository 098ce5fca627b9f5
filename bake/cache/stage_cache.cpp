#include "exitance/bake/cache/stage_cache.h"

#include <fstream>
#include <iterator>
#include <stdexcept>
#include <system_error>

#include <nlohmann/json.hpp>

#include "exitance/bake/cache/cache_entry_folder.h"
#include "exitance/bake/cache/sha256_stream.h"

namespace exitance {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr const char* kEntryFile = "entry.json";
constexpr const char* kEntryFormat = "exitance-stage-cache-entry";
constexpr int kEntryVersion = 1;

std::string sha256_of_bytes(const std::vector<uint8_t>& bytes) {
  Sha256Stream h;
  h.bytes(bytes.data(), bytes.size());
  return h.hex();
}

// The whole file in one read (an istreambuf_iterator copies it a character at a time).
std::vector<uint8_t> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error(path.filename().string() + " cannot be read");
  const std::streamoff size = in.tellg();
  if (size < 0) throw std::runtime_error(path.filename().string() + " cannot be read");
  std::vector<uint8_t> bytes(static_cast<size_t>(size));
  in.seekg(0);
  if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size))
    throw std::runtime_error(path.filename().string() + " cannot be read whole");
  return bytes;
}

// A name an entry may list: plain, not entry.json, not hidden, so a damaged entry.json cannot
// point outside its folder.
bool is_plain_name(const std::string& name) {
  return !name.empty() && name != kEntryFile && name[0] != '.' && name.find('/') == std::string::npos &&
         name.find('\\') == std::string::npos;
}

// The entry's files, each checked against entry.json; throws std::runtime_error naming the problem.
StageEntry read_entry(const fs::path& folder, const std::string& stage, const std::string& key) {
  std::ifstream in(folder / kEntryFile);
  if (!in) throw std::runtime_error("entry.json is missing");
  json entry;
  try {
    entry = json::parse(in);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("entry.json does not parse (") + e.what() + ")");
  }
  if (entry.value("format", "") != kEntryFormat || entry.value("version", 0) != kEntryVersion)
    throw std::runtime_error("entry.json is not a version-1 stage cache entry");
  if (entry.value("stage", "") != stage || entry.value("key", "") != key)
    throw std::runtime_error("entry.json names another stage or key");
  StageEntry result;
  result.warnings = entry.at("warnings").get<std::vector<std::string>>();
  for (const auto& [name, file] : entry.at("files").items()) {
    if (!is_plain_name(name)) throw std::runtime_error("entry.json lists a file name that is not plain");
    std::vector<uint8_t> bytes = read_bytes(folder / name);
    if (bytes.size() != file.at("bytes").get<uintmax_t>())
      throw std::runtime_error(name + " has " + std::to_string(bytes.size()) + " bytes, entry.json says " +
                               std::to_string(file.at("bytes").get<uintmax_t>()));
    if (sha256_of_bytes(bytes) != file.at("sha256").get<std::string>())
      throw std::runtime_error(name + " does not match its SHA-256");
    result.files[name] = std::move(bytes);
  }
  for (const fs::directory_entry& e : fs::directory_iterator(folder)) {
    const std::string name = e.path().filename().string();
    if (name != kEntryFile && result.files.count(name) == 0)
      throw std::runtime_error(name + " is not listed in entry.json");
  }
  return result;
}

}  // namespace

StageCache::StageCache(fs::path directory) : directory_(std::move(directory)) {}

fs::path StageCache::entry_folder(const std::string& stage, const std::string& key) const {
  return directory_ / "v1" / "stages" / stage / key;
}

std::optional<StageEntry> StageCache::restore(const std::string& stage, const std::string& key,
                                              Diagnostics& diagnostics) const {
  const fs::path folder = entry_folder(stage, key);
  std::error_code error;
  if (!fs::is_directory(folder, error)) return std::nullopt;
  try {
    return read_entry(folder, stage, key);
  } catch (const std::exception& e) {
    reject(stage, key, e.what(), diagnostics);
    return std::nullopt;
  }
}

void StageCache::reject(const std::string& stage, const std::string& key, const std::string& problem,
                        Diagnostics& diagnostics) const {
  const fs::path folder = entry_folder(stage, key);
  diagnostics.warn("cache " + folder.string() + ": " + problem + "; computing the " + stage + " stage again");
  cache_entry::discard(folder);
}

void StageCache::store(const std::string& stage, const std::string& key, const StageEntry& entry,
                       Diagnostics& diagnostics) const {
  const fs::path folder = entry_folder(stage, key);
  const fs::path staging = folder.parent_path() / (".staging-" + key + "-" + cache_entry::unique_suffix());
  try {
    fs::create_directories(staging);
    json listing = {{"format", kEntryFormat}, {"version", kEntryVersion}, {"stage", stage},
                    {"key", key},             {"warnings", entry.warnings}, {"files", json::object()}};
    for (const auto& [name, bytes] : entry.files) {
      if (!is_plain_name(name)) throw std::logic_error("stage cache file name '" + name + "' is not plain");
      std::ofstream out(staging / name, std::ios::binary);
      out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
      if (!out) throw std::runtime_error("cannot write " + (staging / name).string());
      listing["files"][name] = {{"bytes", bytes.size()}, {"sha256", sha256_of_bytes(bytes)}};
    }
    {
      std::ofstream out(staging / kEntryFile);
      out << listing.dump(1) << "\n";
      if (!out) throw std::runtime_error("cannot write " + (staging / kEntryFile).string());
    }
    cache_entry::publish(staging, folder);
  } catch (const std::exception& e) {
    std::error_code ignored;
    fs::remove_all(staging, ignored);
    diagnostics.warn("cache " + directory_.string() + ": could not store the " + stage + " stage (" +
                     std::string(e.what()) + ")");
  }
}

}  // namespace exitance
