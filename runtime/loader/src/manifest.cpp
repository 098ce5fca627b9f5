#include "exitance/loader/manifest.h"

#include <cmath>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>

#include "exitance/formats/format_error.h"
#include "exitance/formats/probes_file.h"
#include "exitance/formats/sparse_voxel_octree.h"

namespace exitance::loader {
namespace {

using nlohmann::json;
using formats::FormatError;

// Largest page edge accepted; well above --max-page's useful range, small enough that
// width * height * channels cannot overflow anything.
constexpr uint64_t kMaxPageEdge = 65536;

// Every helper takes the JSON path of the value ("pages[0].width") for its messages.
class FieldReader {
 public:
  explicit FieldReader(const std::string& file) : file_(file) {}

  [[noreturn]] void fail(const std::string& where, const std::string& problem) const {
    throw FormatError(file_ + ": " + where + ": " + problem);
  }

  const json& member(const json& object, const std::string& where, const char* key) const {
    const std::string path = where.empty() ? key : where + "." + key;
    if (!object.is_object()) fail(where.empty() ? "top level" : where, std::string("expected an object, got ") + object.type_name());
    const auto it = object.find(key);
    if (it == object.end()) fail(path, "missing");
    return *it;
  }

  const json& array(const json& value, const std::string& where, std::optional<size_t> exact_size = std::nullopt) const {
    if (!value.is_array()) fail(where, std::string("expected an array, got ") + value.type_name());
    if (exact_size && value.size() != *exact_size)
      fail(where, "expected " + std::to_string(*exact_size) + " elements, got " + std::to_string(value.size()));
    return value;
  }

  uint64_t unsigned_integer(const json& value, const std::string& where, uint64_t min, uint64_t max) const {
    uint64_t v = 0;
    if (value.is_number_unsigned()) {
      v = value.get<uint64_t>();
    } else if (value.is_number_integer()) {
      const int64_t s = value.get<int64_t>();
      if (s < 0) fail(where, std::to_string(s) + " is negative");
      v = uint64_t(s);
    } else {
      fail(where, std::string("expected an integer, got ") + value.type_name());
    }
    if (v < min || v > max)
      fail(where, std::to_string(v) + " is outside " + std::to_string(min) + ".." + std::to_string(max));
    return v;
  }

  float finite_float(const json& value, const std::string& where) const {
    if (!value.is_number()) fail(where, std::string("expected a number, got ") + value.type_name());
    const double v = value.get<double>();
    if (!std::isfinite(v) || std::fabs(v) > double(std::numeric_limits<float>::max()))
      fail(where, "not a finite 32-bit float");
    return float(v);
  }

  template <size_t N>
  std::array<float, N> float_array(const json& value, const std::string& where) const {
    array(value, where, N);
    std::array<float, N> out{};
    for (size_t i = 0; i < N; ++i) out[i] = finite_float(value[i], where + "[" + std::to_string(i) + "]");
    return out;
  }

  std::string string(const json& value, const std::string& where) const {
    if (!value.is_string()) fail(where, std::string("expected a string, got ") + value.type_name());
    std::string s = value.get<std::string>();
    if (s.find('\0') != std::string::npos) fail(where, "contains a NUL character");
    return s;
  }

  // A bundle file: a plain relative path that stays inside the bundle folder, so a hostile
  // manifest cannot make the loader open arbitrary files.
  std::string bundle_file(const json& value, const std::string& where) const {
    const std::string s = string(value, where);
    if (s.empty()) fail(where, "empty file name");
    const std::filesystem::path path(s);
    if (path.has_root_path()) fail(where, "\"" + s + "\" is not a path relative to the bundle");
    for (const auto& part : path)
      if (part == "..") fail(where, "\"" + s + "\" leaves the bundle folder");
    return s;
  }

 private:
  const std::string& file_;
};

PageInfo parse_page(const FieldReader& r, const json& j, const std::string& where) {
  PageInfo page;
  page.file = r.bundle_file(r.member(j, where, "file"), where + ".file");
  page.width = uint32_t(r.unsigned_integer(r.member(j, where, "width"), where + ".width", 1, kMaxPageEdge));
  page.height = uint32_t(r.unsigned_integer(r.member(j, where, "height"), where + ".height", 1, kMaxPageEdge));
  const json& channels = r.array(r.member(j, where, "channels"), where + ".channels");
  for (size_t c = 0; c < channels.size(); ++c)
    page.channels.push_back(r.string(channels[c], where + ".channels[" + std::to_string(c) + "]"));
  return page;
}

InstanceInfo parse_instance(const FieldReader& r, const json& j, const std::string& where, size_t page_count) {
  constexpr uint64_t kMaxIndex = std::numeric_limits<uint32_t>::max();
  InstanceInfo instance;
  instance.node = uint32_t(r.unsigned_integer(r.member(j, where, "node"), where + ".node", 0, kMaxIndex));
  instance.name = r.string(r.member(j, where, "name"), where + ".name");
  instance.mesh = uint32_t(r.unsigned_integer(r.member(j, where, "mesh"), where + ".mesh", 0, kMaxIndex));
  const json& page = r.member(j, where, "page");
  const uint64_t page_index = r.unsigned_integer(page, where + ".page", 0, kMaxIndex);
  if (page_index >= page_count)
    r.fail(where + ".page", std::to_string(page_index) + " is not a page (" + std::to_string(page_count) + " pages)");
  instance.page = uint32_t(page_index);
  instance.scale_offset = r.float_array<4>(r.member(j, where, "scale_offset"), where + ".scale_offset");
  if (j.contains("rect")) {  // optional: the instance's texel rectangle
    const json& rect = r.array(j["rect"], where + ".rect", 4);
    std::array<uint32_t, 4> v{};
    for (size_t i = 0; i < 4; ++i)
      v[i] = uint32_t(r.unsigned_integer(rect[i], where + ".rect[" + std::to_string(i) + "]", 0, kMaxPageEdge));
    instance.rect = v;
  }
  return instance;
}

ProbeGridInfo parse_probes(const FieldReader& r, const json& j) {
  const std::string where = "probes";
  ProbeGridInfo probes;
  probes.file = r.bundle_file(r.member(j, where, "file"), where + ".file");
  probes.origin = r.float_array<3>(r.member(j, where, "origin"), where + ".origin");
  probes.spacing = r.float_array<3>(r.member(j, where, "spacing"), where + ".spacing");
  for (size_t a = 0; a < 3; ++a)
    if (!(probes.spacing[a] > 0)) r.fail(where + ".spacing[" + std::to_string(a) + "]", "not positive");
  const json& counts = r.array(r.member(j, where, "counts"), where + ".counts", 3);
  uint64_t total = 1;
  for (size_t a = 0; a < 3; ++a) {
    probes.counts[a] = uint32_t(
        r.unsigned_integer(counts[a], where + ".counts[" + std::to_string(a) + "]", 1, formats::kMaxProbeCount));
    total *= probes.counts[a];  // each factor <= 2^26 and checked below after every step
    if (total > formats::kMaxProbeCount)
      r.fail(where + ".counts", "more than " + std::to_string(formats::kMaxProbeCount) + " probes");
  }
  probes.sh_order = uint32_t(r.unsigned_integer(r.member(j, where, "sh_order"), where + ".sh_order", 2, 2));
  return probes;
}

SvoInfo parse_svo(const FieldReader& r, const json& j) {
  const std::string where = "svo";
  SvoInfo svo;
  svo.file = r.bundle_file(r.member(j, where, "file"), where + ".file");
  const json& bounds = r.array(r.member(j, where, "bounds"), where + ".bounds", 2);
  svo.bounds_min = r.float_array<3>(bounds[0], where + ".bounds[0]");
  svo.bounds_max = r.float_array<3>(bounds[1], where + ".bounds[1]");
  for (size_t a = 0; a < 3; ++a)
    if (!(svo.bounds_max[a] > svo.bounds_min[a])) r.fail(where + ".bounds", "maximum not above minimum");
  svo.depth = uint32_t(r.unsigned_integer(r.member(j, where, "depth"), where + ".depth", 0, formats::kSvoMaxDepth));
  return svo;
}

}  // namespace

Manifest parse_manifest(std::string_view json_text, const std::string& name) {
  json root;
  try {
    root = json::parse(json_text.begin(), json_text.end());
  } catch (const json::exception& e) {
    throw FormatError(name + ": not valid JSON: " + e.what());
  }
  const FieldReader r(name);
  if (!root.is_object()) r.fail("top level", std::string("expected an object, got ") + root.type_name());

  Manifest manifest;
  const uint64_t version =
      r.unsigned_integer(r.member(root, "", "format_version"), "format_version", 0, std::numeric_limits<uint32_t>::max());
  if (version != kManifestFormatVersion)
    throw FormatError(name + ": format version " + std::to_string(version) +
                      (version > kManifestFormatVersion ? " is newer than this loader (" : " is older than this loader supports (") +
                      std::to_string(kManifestFormatVersion) + ")");
  manifest.format_version = uint32_t(version);
  if (root.contains("generator") && root["generator"].is_string()) manifest.generator = r.string(root["generator"], "generator");

  const json& pages = r.array(r.member(root, "", "pages"), "pages");
  for (size_t p = 0; p < pages.size(); ++p) manifest.pages.push_back(parse_page(r, pages[p], "pages[" + std::to_string(p) + "]"));
  const json& instances = r.array(r.member(root, "", "instances"), "instances");
  for (size_t i = 0; i < instances.size(); ++i)
    manifest.instances.push_back(
        parse_instance(r, instances[i], "instances[" + std::to_string(i) + "]", manifest.pages.size()));
  // "probes" and "svo" are optional; null counts as absent (a bake with --probes none).
  if (root.contains("probes") && !root["probes"].is_null()) manifest.probes = parse_probes(r, root["probes"]);
  if (root.contains("svo") && !root["svo"].is_null()) manifest.svo = parse_svo(r, root["svo"]);
  return manifest;
}

}  // namespace exitance::loader
