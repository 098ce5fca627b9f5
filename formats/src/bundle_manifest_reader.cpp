#include "exitance/formats/bundle_manifest.h"

#include <cmath>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>

#include "exitance/formats/format_error.h"
#include "exitance/formats/probes_file.h"
#include "exitance/formats/sparse_voxel_octree.h"

namespace exitance::formats {
namespace {

using nlohmann::json;

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

  int64_t signed_integer(const json& value, const std::string& where, int64_t min, int64_t max) const {
    if (!value.is_number_integer()) fail(where, std::string("expected an integer, got ") + value.type_name());
    if (value.is_number_unsigned() && value.get<uint64_t>() > uint64_t(max))
      fail(where, std::to_string(value.get<uint64_t>()) + " is above " + std::to_string(max));
    const int64_t v = value.get<int64_t>();
    if (v < min || v > max) fail(where, std::to_string(v) + " is outside " + std::to_string(min) + ".." + std::to_string(max));
    return v;
  }

  double finite_double(const json& value, const std::string& where) const {
    if (!value.is_number()) fail(where, std::string("expected a number, got ") + value.type_name());
    const double v = value.get<double>();
    if (!std::isfinite(v)) fail(where, "not finite");
    return v;
  }

  double non_negative_double(const json& value, const std::string& where) const {
    const double v = finite_double(value, where);
    if (v < 0) fail(where, "negative");
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
        r.unsigned_integer(counts[a], where + ".counts[" + std::to_string(a) + "]", 1, kMaxProbeCount));
    total *= probes.counts[a];  // each factor <= 2^26 and checked below after every step
    if (total > kMaxProbeCount)
      r.fail(where + ".counts", "more than " + std::to_string(kMaxProbeCount) + " probes");
  }
  probes.sh_order = uint32_t(r.unsigned_integer(r.member(j, where, "sh_order"), where + ".sh_order", 2, 2));
  // Placement counts: all four or none.
  if (j.contains("valid") || j.contains("moved") || j.contains("invalid") || j.contains("skipped")) {
    ProbePlacementCounts c;
    c.valid = r.unsigned_integer(r.member(j, where, "valid"), where + ".valid", 0, total);
    c.moved = r.unsigned_integer(r.member(j, where, "moved"), where + ".moved", 0, total);
    c.invalid = r.unsigned_integer(r.member(j, where, "invalid"), where + ".invalid", 0, total);
    c.skipped = r.unsigned_integer(r.member(j, where, "skipped"), where + ".skipped", 0, total);
    probes.placement = c;
  }
  return probes;
}

SvoInfo parse_svo(const FieldReader& r, const json& j) {
  const std::string where = "svo";
  SvoInfo svo;
  if (j.contains("nodes")) svo.nodes = r.unsigned_integer(j["nodes"], where + ".nodes", 0, UINT64_MAX);
  if (j.contains("vdb")) svo.vdb = r.bundle_file(j["vdb"], where + ".vdb");
  if (j.contains("vdb_note")) svo.vdb_note = r.string(j["vdb_note"], where + ".vdb_note");
  svo.file = r.bundle_file(r.member(j, where, "file"), where + ".file");
  const json& bounds = r.array(r.member(j, where, "bounds"), where + ".bounds", 2);
  svo.bounds_min = r.float_array<3>(bounds[0], where + ".bounds[0]");
  svo.bounds_max = r.float_array<3>(bounds[1], where + ".bounds[1]");
  for (size_t a = 0; a < 3; ++a)
    if (!(svo.bounds_max[a] > svo.bounds_min[a])) r.fail(where + ".bounds", "maximum not above minimum");
  svo.depth = uint32_t(r.unsigned_integer(r.member(j, where, "depth"), where + ".depth", 0, kSvoMaxDepth));
  return svo;
}


SceneFileInfo parse_scene(const FieldReader& r, const json& j) {
  const std::string where = "scene";
  SceneFileInfo scene;
  if (j.is_object() && j.contains("skipped")) {
    scene.skipped = r.string(j["skipped"], where + ".skipped");
    if (scene.skipped.empty()) r.fail(where + ".skipped", "empty reason");
    if (j.contains("file")) r.fail(where, "both a file and a reason it was skipped");
    return scene;
  }
  scene.file = r.bundle_file(r.member(j, where, "file"), where + ".file");
  scene.format_version =
      uint32_t(r.unsigned_integer(r.member(j, where, "format_version"), where + ".format_version", 1, UINT32_MAX));
  scene.bytes = r.unsigned_integer(r.member(j, where, "bytes"), where + ".bytes", 1, UINT64_MAX);
  return scene;
}

// The largest preview image edge, as exitance-view's --size.
constexpr uint64_t kMaxPreviewEdge = 16384;

PreviewViewInfo parse_preview_view(const FieldReader& r, const json& j, const std::string& where) {
  PreviewViewInfo view;
  view.file = r.bundle_file(r.member(j, where, "file"), where + ".file");
  view.camera = r.string(r.member(j, where, "camera"), where + ".camera");
  view.look_from = r.float_array<3>(r.member(j, where, "look_from"), where + ".look_from");
  view.look_at = r.float_array<3>(r.member(j, where, "look_at"), where + ".look_at");
  if (view.look_at == view.look_from) r.fail(where + ".look_at", "equals look_from");
  view.up = r.float_array<3>(r.member(j, where, "up"), where + ".up");
  if (view.up == std::array<float, 3>{0, 0, 0}) r.fail(where + ".up", "zero vector");
  view.yfov = r.finite_float(r.member(j, where, "yfov"), where + ".yfov");
  if (!(view.yfov > 0 && view.yfov < 3.14159265f)) r.fail(where + ".yfov", "not in (0, pi)");
  view.width = uint32_t(r.unsigned_integer(r.member(j, where, "width"), where + ".width", 1, kMaxPreviewEdge));
  view.height = uint32_t(r.unsigned_integer(r.member(j, where, "height"), where + ".height", 1, kMaxPreviewEdge));
  return view;
}

PreviewInfo parse_preview(const FieldReader& r, const json& j, size_t page_count) {
  const std::string where = "preview";
  PreviewInfo preview;
  const json& pages = r.array(r.member(j, where, "pages"), where + ".pages", page_count);
  for (size_t p = 0; p < pages.size(); ++p)
    preview.pages.push_back(r.bundle_file(pages[p], where + ".pages[" + std::to_string(p) + "]"));
  const json& views = r.array(r.member(j, where, "views"), where + ".views");
  for (size_t v = 0; v < views.size(); ++v)
    preview.views.push_back(parse_preview_view(r, views[v], where + ".views[" + std::to_string(v) + "]"));
  if (j.contains("views_skipped")) {
    preview.views_skipped = r.string(j["views_skipped"], where + ".views_skipped");
    if (preview.views_skipped.empty()) r.fail(where + ".views_skipped", "empty reason");
    if (!preview.views.empty()) r.fail(where, "both views and a reason there are none");
  }
  return preview;
}

InputInfo parse_input(const FieldReader& r, const json& j) {
  InputInfo input;
  input.file = r.string(r.member(j, "input", "file"), "input.file");
  input.sha256 = r.string(r.member(j, "input", "sha256"), "input.sha256");
  if (input.sha256.size() != 64 || input.sha256.find_first_not_of("0123456789abcdef") != std::string::npos)
    r.fail("input.sha256", "not 64 lowercase hexadecimal digits");
  return input;
}

// A setting that may be a number or the string "none" (an optional stage turned off).
template <typename Read>
auto number_or_none(const FieldReader& r, const json& j, const std::string& where, Read read)
    -> std::optional<decltype(read(j))> {
  if (j.is_string()) {
    if (j.get<std::string>() != "none") r.fail(where, "expected a number or \"none\"");
    return std::nullopt;
  }
  return read(j);
}

BakeSettings parse_settings(const FieldReader& r, const json& j) {
  const std::string where = "settings";
  if (!j.is_object()) r.fail(where, std::string("expected an object, got ") + j.type_name());
  BakeSettings s;
  auto field = [&](const char* key) -> const json* { return j.contains(key) ? &j[key] : nullptr; };
  auto path = [&](const char* key) { return where + "." + key; };
  constexpr int64_t kIntMax = std::numeric_limits<int32_t>::max();
  if (auto v = field("backend")) {
    s.backend = r.string(*v, path("backend"));
    if (s.backend != "cpu" && s.backend != "vulkan") r.fail(path("backend"), "\"" + s.backend + "\" is not cpu or vulkan");
  }
  if (auto v = field("integrator")) {
    s.integrator = r.string(*v, path("integrator"));
    if (s.integrator != "path" && s.integrator != "bounces")
      r.fail(path("integrator"), "\"" + s.integrator + "\" is not path or bounces");
  }
  if (auto v = field("spp")) s.spp = uint32_t(r.unsigned_integer(*v, path("spp"), 0, UINT32_MAX));
  if (auto v = field("time_budget_seconds")) s.time_budget_seconds = r.non_negative_double(*v, path("time_budget_seconds"));
  if (auto v = field("target_error")) s.target_error = r.non_negative_double(*v, path("target_error"));
  if (auto v = field("adaptive")) {
    if (!v->is_boolean()) r.fail(path("adaptive"), std::string("expected true or false, got ") + v->type_name());
    s.adaptive = v->get<bool>();
  }
  if (auto v = field("first_bounce")) {
    s.first_bounce = r.string(*v, path("first_bounce"));
    if (s.first_bounce != "traced" && s.first_bounce != "cached")
      r.fail(path("first_bounce"), "\"" + s.first_bounce + "\" is not traced or cached");
  }
  if (auto v = field("sampler")) {
    s.sampler = r.string(*v, path("sampler"));
    if (s.sampler != "sobol" && s.sampler != "independent")
      r.fail(path("sampler"), "\"" + s.sampler + "\" is not sobol or independent");
  }
  if (auto v = field("directional")) {
    s.directional = r.string(*v, path("directional"));
    if (s.directional != "off" && s.directional != "sh1")
      r.fail(path("directional"), "\"" + s.directional + "\" is not off or sh1");
  }
  if (auto v = field("bounces")) s.bounces = int32_t(r.signed_integer(*v, path("bounces"), -1, kIntMax));
  if (auto v = field("seed")) s.seed = r.unsigned_integer(*v, path("seed"), 0, UINT64_MAX);
  if (auto v = field("texel_density")) s.texel_density = r.non_negative_double(*v, path("texel_density"));
  if (auto v = field("max_page")) s.max_page = uint32_t(r.unsigned_integer(*v, path("max_page"), 1, kMaxPageEdge));
  if (auto v = field("padding")) s.padding = uint32_t(r.unsigned_integer(*v, path("padding"), 0, kMaxPageEdge));
  if (auto v = field("lightmap_uv")) {
    if (v->is_string()) {
      if (v->get<std::string>() != "generate") r.fail(path("lightmap_uv"), "expected 0, 1 or \"generate\"");
      s.lightmap_uv_generate = true;
    } else {
      s.lightmap_uv = uint32_t(r.unsigned_integer(*v, path("lightmap_uv"), 0, 1));
    }
  }
  if (auto v = field("generated_uv_meshes")) {
    if (!v->is_array()) r.fail(path("generated_uv_meshes"), std::string("expected an array, got ") + v->type_name());
    for (size_t i = 0; i < v->size(); ++i)
      s.generated_uv_meshes.push_back(uint32_t(r.unsigned_integer(
          (*v)[i], path("generated_uv_meshes") + "[" + std::to_string(i) + "]", 0, UINT32_MAX)));
  }
  if (auto v = field("russian_roulette_start"))
    s.russian_roulette_start = int32_t(r.signed_integer(*v, path("russian_roulette_start"), 0, kIntMax));
  if (auto v = field("safety_bounce_cap"))
    s.safety_bounce_cap = int32_t(r.signed_integer(*v, path("safety_bounce_cap"), 1, kIntMax));
  if (auto v = field("sky")) s.sky = r.string(*v, path("sky"));
  if (auto v = field("probes"))
    s.probe_spacing = number_or_none(r, *v, path("probes"), [&](const json& x) {
      const float spacing = r.finite_float(x, path("probes"));
      if (!(spacing > 0)) r.fail(path("probes"), "not positive");
      return spacing;
    });
  if (auto v = field("probe_spp")) s.probe_spp = uint32_t(r.unsigned_integer(*v, path("probe_spp"), 1, UINT32_MAX));
  if (auto v = field("probe_dering_window")) s.probe_dering_window = float(r.non_negative_double(*v, path("probe_dering_window")));
  if (auto v = field("voxel_resolution"))
    s.voxel_resolution = number_or_none(r, *v, path("voxel_resolution"), [&](const json& x) {
      return uint32_t(r.unsigned_integer(x, path("voxel_resolution"), 1, UINT32_MAX));
    });
  return s;
}

LightLayersInfo parse_light_layers(const FieldReader& r, const json& j, size_t page_count) {
  const std::string where = "light_layers";
  LightLayersInfo layers;
  layers.count = uint32_t(r.unsigned_integer(r.member(j, where, "count"), where + ".count", 1, kMaxManifestLightLayers));
  layers.punctual = uint32_t(r.unsigned_integer(r.member(j, where, "punctual"), where + ".punctual", 0, layers.count - 1));
  const json& files = r.array(r.member(j, where, "files"), where + ".files", page_count);
  for (size_t p = 0; p < files.size(); ++p) {
    layers.files.push_back(r.bundle_file(files[p], where + ".files[" + std::to_string(p) + "]"));
    for (size_t q = 0; q < p; ++q)
      if (layers.files[q] == layers.files[p]) r.fail(where + ".files[" + std::to_string(p) + "]", "\"" + layers.files[p] + "\" is listed twice");
  }
  return layers;
}

// A free-form block, kept as text.
std::string object_text(const FieldReader& r, const json& j, const std::string& where) {
  if (!j.is_object()) r.fail(where, std::string("expected an object, got ") + j.type_name());
  return j.dump();
}

}  // namespace

bool BundleManifest::has_bounce_layers() const {
  for (const PageInfo& page : pages)
    for (const std::string& channel : page.channels)
      if (channel.rfind("bounce", 0) == 0) return true;
  return false;
}

BundleManifest parse_bundle_manifest(std::string_view json_text, const std::string& name) {
  json root;
  try {
    root = json::parse(json_text.begin(), json_text.end());
  } catch (const json::exception& e) {
    throw FormatError(name + ": not valid JSON: " + e.what());
  }
  const FieldReader r(name);
  if (!root.is_object()) r.fail("top level", std::string("expected an object, got ") + root.type_name());

  BundleManifest manifest;
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
  if (root.contains("scene")) manifest.scene = parse_scene(r, root["scene"]);
  if (root.contains("preview")) manifest.preview = parse_preview(r, root["preview"], manifest.pages.size());
  if (root.contains("light_layers")) manifest.light_layers = parse_light_layers(r, root["light_layers"], manifest.pages.size());
  if (root.contains("input")) manifest.input = parse_input(r, root["input"]);
  if (root.contains("settings")) manifest.settings = parse_settings(r, root["settings"]);
  if (root.contains("stats")) manifest.stats_json = object_text(r, root["stats"], "stats");
  if (root.contains("relight")) manifest.relight_json = object_text(r, root["relight"], "relight");
  return manifest;
}

}  // namespace exitance::formats
