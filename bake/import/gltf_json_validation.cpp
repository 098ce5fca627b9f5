#include "exitance/bake/import/gltf_json_validation.h"

#include <algorithm>
#include <filesystem>
#include <limits>
#include <set>
#include <vector>

#include "exitance/bake/import/gltf_file_load.h"
#include "exitance/bake/input_error.h"

namespace exitance {
namespace {

using json = nlohmann::json;

constexpr int64_t kIntMax = std::numeric_limits<int64_t>::max();
constexpr uint64_t kMaxExternalFileBytes = uint64_t(4) << 30;

// glTF componentType and type codes (the GL enums the spec uses).
constexpr int64_t kByte = 5120, kUnsignedByte = 5121, kShort = 5122, kUnsignedShort = 5123, kUnsignedInt = 5125,
                  kFloat = 5126;
constexpr int64_t kTriangles = 4;

// Where a problem lies: the element ("accessor 3") and the member path inside it ("sparse.indices.").
struct Where {
  std::string element;
  std::string path;
  Where in(const std::string& key) const { return {element, path + key + "."}; }
};

std::string describe(const json& v) {
  switch (v.type()) {
    case json::value_t::object: return "an object";
    case json::value_t::array: return "an array";
    case json::value_t::string: return "a string";
    case json::value_t::boolean: return "a boolean";
    case json::value_t::null: return "null";
    case json::value_t::number_float: return "a fractional number";
    default: return "a number";
  }
}

// A uri quoted in a message: printable characters only, at most 80 of them.
std::string shown(const std::string& text) {
  std::string out;
  for (char c : text.substr(0, 80)) out += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
  return "'" + out + (text.size() > 80 ? "...'" : "'");
}

int component_size(int64_t component_type) {
  switch (component_type) {
    case kByte: case kUnsignedByte: return 1;
    case kShort: case kUnsignedShort: return 2;
    case kUnsignedInt: case kFloat: return 4;
    default: return 0;
  }
}

int type_components(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4" || type == "MAT2") return 4;
  if (type == "MAT3") return 9;
  if (type == "MAT4") return 16;
  return 0;
}

// Bytes of one element, with the column padding the spec requires for small matrices.
uint64_t element_size(int64_t component_type, const std::string& type) {
  const uint64_t c = uint64_t(component_size(component_type));
  if (type == "MAT2" && c == 1) return 8;
  if (type == "MAT3" && c == 1) return 12;
  if (type == "MAT3" && c == 2) return 24;
  return c * uint64_t(type_components(type));
}

// Overflow-safe: do `count` elements of `size` bytes, `stride` apart from `offset`, fit in `length` bytes?
bool fits(uint64_t offset, uint64_t count, uint64_t size, uint64_t stride, uint64_t length) {
  if (offset > length || size > length - offset) return false;
  return count == 0 || stride == 0 || count - 1 <= (length - offset - size) / stride;
}

std::optional<std::pair<int, int>> parse_version(const std::string& text) {
  const size_t dot = text.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == text.size() || dot > 4 || text.size() - dot > 5)
    return std::nullopt;
  for (size_t i = 0; i < text.size(); ++i)
    if (i != dot && (text[i] < '0' || text[i] > '9')) return std::nullopt;
  return std::make_pair(std::stoi(text.substr(0, dot)), std::stoi(text.substr(dot + 1)));
}

bool is_base64_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '+' || c == '/';
}

// Decoded length of strict base64 text (optional '=' padding); nullopt when it is not base64.
std::optional<uint64_t> base64_decoded_size(const std::string& text, size_t begin) {
  size_t end = text.size();
  size_t padding = 0;
  while (end > begin && text[end - 1] == '=' && padding < 2) --end, ++padding;
  for (size_t i = begin; i < end; ++i)
    if (!is_base64_char(text[i])) return std::nullopt;
  const uint64_t n = end - begin;
  if (n % 4 == 1 || (padding > 0 && (n + padding) % 4 != 0)) return std::nullopt;
  return n / 4 * 3 + (n % 4 == 0 ? 0 : n % 4 - 1);
}

bool has_uri_scheme(const std::string& uri) {
  const size_t colon = uri.find(':');
  if (colon == std::string::npos || colon == 0) return false;
  for (size_t i = 0; i < colon; ++i) {
    const char c = uri[i];
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (i > 0 && ((c >= '0' && c <= '9') || c == '+' ||
                                                                                  c == '-' || c == '.'));
    if (!ok) return false;
  }
  return true;
}

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Percent-decoding as tinygltf does it ('+' is a space), but refusing malformed escapes and NUL.
std::optional<std::string> percent_decode(const std::string& uri) {
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '+') {
      out += ' ';
    } else if (uri[i] == '%') {
      if (i + 2 >= uri.size() || hex_value(uri[i + 1]) < 0 || hex_value(uri[i + 2]) < 0) return std::nullopt;
      out += char(hex_value(uri[i + 1]) * 16 + hex_value(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  if (out.empty() || out.find('\0') != std::string::npos) return std::nullopt;
  return out;
}

struct BufferViewInfo { uint64_t buffer, offset, length, stride; };
struct AccessorInfo { int64_t component_type; std::string type; bool normalized; uint64_t count; int64_t view; };

class Validator {
 public:
  Validator(const json& document, const std::string& file, const std::string& base_dir,
            std::optional<uint64_t> glb_bin_size)
      : doc_(document), file_(file), base_dir_(base_dir), glb_bin_size_(glb_bin_size) {}

  GltfExternalFiles run() {
    if (!doc_.is_object()) raise("glTF", "the top level is " + describe(doc_) + ", not a JSON object");
    check_asset();
    check_extension_lists();
    extensions(doc_, Where{"glTF", ""});
    for (const char* key : {"scenes", "nodes", "meshes", "accessors", "bufferViews", "buffers", "materials", "textures",
                            "images", "samplers", "cameras", "skins", "animations"})
      top_array(key);
    check_lights();
    check_scenes();
    check_nodes();
    check_buffers();
    check_buffer_views();
    check_accessors();
    check_meshes();
    check_images();
    check_samplers();
    check_textures();
    check_materials();
    return files_;
  }

 private:
  // ---- reporting and typed member access -------------------------------------------------------
  // Keys and strings come from the file: control characters would break the one-line error.
  [[noreturn]] void raise(const std::string& element, const std::string& problem) const {
    auto printable = [](std::string text) {
      for (char& c : text)
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
      return text;
    };
    throw InputError(file_, printable(element), printable(problem));
  }
  [[noreturn]] void fail(const Where& w, const std::string& key, const std::string& problem) const {
    raise(w.element, w.path + key + " " + problem);
  }
  [[noreturn]] void fail(const Where& w, const std::string& problem) const {
    raise(w.element, (w.path.empty() ? "" : w.path.substr(0, w.path.size() - 1) + " ") + problem);
  }

  static const json* find(const json& object, const std::string& key) {
    auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
  }

  // JSON integers only: tinygltf silently drops an optional integer written as 1.0 or "1".
  std::optional<int64_t> integer(const json& object, const Where& w, const std::string& key, bool required,
                                 int64_t min = 0, int64_t max = kIntMax) const {
    const json* v = find(object, key);
    if (!v) {
      if (required) fail(w, key, "is required");
      return std::nullopt;
    }
    if (!v->is_number_integer()) fail(w, key, "must be an integer, not " + describe(*v));
    if (v->is_number_unsigned() && v->get<uint64_t>() > uint64_t(kIntMax))
      fail(w, key, std::to_string(v->get<uint64_t>()) + " is out of range");
    const int64_t value = v->get<int64_t>();
    if (value < min || value > max)
      fail(w, key, std::to_string(value) + (max == kIntMax ? " must be >= " + std::to_string(min)
                                                           : " is not in [" + std::to_string(min) + ", " +
                                                                 std::to_string(max) + "]"));
    return value;
  }

  // A glTFid: an integer naming an existing item of `target` (count items).
  std::optional<int64_t> index(const json& object, const Where& w, const std::string& key, size_t count,
                               const std::string& target, bool required) const {
    const auto value = integer(object, w, key, required);
    if (value && uint64_t(*value) >= count)
      fail(w, key, key == target ? std::to_string(*value) + " does not exist"
                                 : "names " + target + " " + std::to_string(*value) + ", which does not exist");
    return value;
  }

  std::optional<double> number(const json& object, const Where& w, const std::string& key, bool required,
                               double min = -std::numeric_limits<double>::max()) const {
    const json* v = find(object, key);
    if (!v) {
      if (required) fail(w, key, "is required");
      return std::nullopt;
    }
    if (!v->is_number()) fail(w, key, "must be a number, not " + describe(*v));
    const double value = v->get<double>();
    if (value < min) fail(w, key, "must be >= " + std::to_string(min));
    return value;
  }

  std::optional<std::string> string(const json& object, const Where& w, const std::string& key, bool required) const {
    const json* v = find(object, key);
    if (!v) {
      if (required) fail(w, key, "is required");
      return std::nullopt;
    }
    if (!v->is_string()) fail(w, key, "must be a string, not " + describe(*v));
    return v->get<std::string>();
  }

  void boolean(const json& object, const Where& w, const std::string& key) const {
    const json* v = find(object, key);
    if (v && !v->is_boolean()) fail(w, key, "must be true or false, not " + describe(*v));
  }

  const json* object_member(const json& object, const Where& w, const std::string& key, bool required) const {
    const json* v = find(object, key);
    if (!v) {
      if (required) fail(w, key, "is required");
      return nullptr;
    }
    if (!v->is_object()) fail(w, key, "must be a JSON object, not " + describe(*v));
    return v;
  }

  const json* array_member(const json& object, const Where& w, const std::string& key, bool required) const {
    const json* v = find(object, key);
    if (!v) {
      if (required) fail(w, key, "is required");
      return nullptr;
    }
    if (!v->is_array()) fail(w, key, "must be an array, not " + describe(*v));
    return v;
  }

  // An array of numbers, of exactly `size` items when size > 0.
  void number_array(const json& object, const Where& w, const std::string& key, size_t size) const {
    const json* v = array_member(object, w, key, false);
    if (!v) return;
    if (size > 0 && v->size() != size)
      fail(w, key, "must have " + std::to_string(size) + " numbers, not " + std::to_string(v->size()));
    for (const json& item : *v)
      if (!item.is_number()) fail(w, key, "must hold numbers only, not " + describe(item));
  }

  // An array of glTFids naming items of `target`, each at most once.
  void index_array(const json& object, const Where& w, const std::string& key, size_t count,
                   const std::string& target) const {
    const json* v = array_member(object, w, key, false);
    if (!v) return;
    std::set<int64_t> seen;
    for (size_t i = 0; i < v->size(); ++i) {
      const json& item = (*v)[i];
      const std::string name = key + "[" + std::to_string(i) + "]";
      if (!item.is_number_integer() || (item.is_number_unsigned() && item.get<uint64_t>() > uint64_t(kIntMax)))
        fail(w, name, "must be an integer index, not " + describe(item));
      const int64_t value = item.get<int64_t>();
      if (value < 0 || uint64_t(value) >= count)
        fail(w, name, "names " + target + " " + std::to_string(value) + ", which does not exist");
      if (!seen.insert(value).second) fail(w, name, "repeats " + target + " " + std::to_string(value));
    }
  }

  // `extensions` is an object of objects; `extras` may be anything.
  void extensions(const json& object, const Where& w) const {
    const json* ext = object_member(object, w, "extensions", false);
    if (!ext) return;
    for (auto it = ext->begin(); it != ext->end(); ++it)
      if (!it->is_object()) fail(w, "extensions." + it.key(), "must be a JSON object, not " + describe(*it));
  }

  const json* extension(const json& object, const std::string& name) const {
    const json* ext = find(object, "extensions");
    return ext ? find(*ext, name) : nullptr;
  }

  // A top-level array of objects ("accessors"); its items are named "accessor N".
  const json& top_array(const std::string& key) const {
    static const json empty = json::array();
    const json* v = find(doc_, key);
    if (!v) return empty;
    if (!v->is_array()) raise(key, "must be an array, not " + describe(*v));
    for (size_t i = 0; i < v->size(); ++i)
      if (!(*v)[i].is_object())
        raise(singular(key) + " " + std::to_string(i), "must be a JSON object, not " + describe((*v)[i]));
    return *v;
  }

  static std::string singular(const std::string& key) {
    if (key == "meshes") return "mesh";
    return key.substr(0, key.size() - 1);
  }

  size_t count(const std::string& key) const {
    const json* v = find(doc_, key);
    return v && v->is_array() ? v->size() : 0;
  }

  // ---- asset and extension lists -----------------------------------------------------------------
  void check_asset() const {
    const Where w{"asset", ""};
    const json* asset = find(doc_, "asset");
    if (!asset) raise("asset", "is missing (every glTF 2.0 file has one)");
    if (!asset->is_object()) fail(w, "must be a JSON object, not " + describe(*asset));
    const std::string version = *string(*asset, w, "version", true);
    const auto parsed = parse_version(version);
    if (!parsed) fail(w, "version", shown(version) + " is not of the form MAJOR.MINOR");
    if (parsed->first != 2) fail(w, "version", shown(version) + " is not supported (need glTF 2.x)");
    if (const auto min_version = string(*asset, w, "minVersion", false)) {
      const auto min_parsed = parse_version(*min_version);
      if (!min_parsed) fail(w, "minVersion", shown(*min_version) + " is not of the form MAJOR.MINOR");
      if (*min_parsed > *parsed) fail(w, "minVersion", *min_version + " is newer than version " + version);
      if (*min_parsed > std::make_pair(2, 0))
        fail(w, "minVersion", *min_version + " needs a loader newer than this one (glTF 2.0)");
    }
    string(*asset, w, "generator", false);
    string(*asset, w, "copyright", false);
    extensions(*asset, w);
  }

  std::set<std::string> string_set(const std::string& key) const {
    std::set<std::string> out;
    const Where w{key, ""};
    const json* v = find(doc_, key);
    if (!v) return out;
    if (!v->is_array()) raise(key, "must be an array, not " + describe(*v));
    for (const json& item : *v) {
      if (!item.is_string()) raise(key, "must hold strings only, not " + describe(item));
      if (!out.insert(item.get<std::string>()).second)
        raise(key, "lists " + shown(item.get<std::string>()) + " twice");
    }
    return out;
  }

  void check_extension_lists() const {
    const std::set<std::string> used = string_set("extensionsUsed");
    for (const std::string& name : string_set("extensionsRequired")) {
      if (!is_supported_gltf_extension(name))
        raise("extensionsRequired", "extension " + shown(name) + " is not supported");
      if (!used.count(name))
        raise("extensionsRequired", "extension " + shown(name) + " is not listed in extensionsUsed");
    }
  }

  // ---- scene graph -------------------------------------------------------------------------------
  void check_lights() {
    const json* ext = extension(doc_, "KHR_lights_punctual");
    if (!ext) return;
    const Where w{"KHR_lights_punctual", ""};
    const json* lights = array_member(*ext, w, "lights", false);
    if (!lights) return;
    light_count_ = lights->size();
    for (size_t i = 0; i < lights->size(); ++i) {
      const json& light = (*lights)[i];
      const Where wl{"light " + std::to_string(i), ""};
      if (!light.is_object()) fail(wl, "must be a JSON object, not " + describe(light));
      const std::string type = *string(light, wl, "type", true);
      if (type != "point" && type != "spot" && type != "directional")
        fail(wl, "type", shown(type) + " is not point, spot or directional");
      number_array(light, wl, "color", 3);
      number(light, wl, "intensity", false, 0.0);
      number(light, wl, "range", false);
      if (const json* spot = object_member(light, wl, "spot", type == "spot")) {
        number(*spot, wl.in("spot"), "innerConeAngle", false);
        number(*spot, wl.in("spot"), "outerConeAngle", false);
      }
      string(light, wl, "name", false);
    }
  }

  void check_scenes() const {
    const json& scenes = top_array("scenes");
    for (size_t i = 0; i < scenes.size(); ++i) {
      const Where w{"scene " + std::to_string(i), ""};
      index_array(scenes[i], w, "nodes", count("nodes"), "node");
      string(scenes[i], w, "name", false);
      extensions(scenes[i], w);
    }
    if (const json* scene = find(doc_, "scene")) {
      if (!scene->is_number_integer())
        raise("scene", "must be an integer index, not " + describe(*scene));
      if (!scene->is_number_unsigned() && scene->get<int64_t>() < 0) raise("scene", scene->dump() + " must be >= 0");
      if (scene->get<uint64_t>() >= scenes.size())
        raise("scene " + scene->dump(),
                         "does not exist (the file has " + std::to_string(scenes.size()) + " scenes)");
    }
  }

  void check_nodes() const {
    const json& nodes = top_array("nodes");
    for (size_t i = 0; i < nodes.size(); ++i) {
      const json& node = nodes[i];
      const Where w{"node " + std::to_string(i), ""};
      index_array(node, w, "children", nodes.size(), "node");
      index(node, w, "camera", count("cameras"), "camera", false);
      index(node, w, "skin", count("skins"), "skin", false);
      index(node, w, "mesh", count("meshes"), "mesh", false);
      number_array(node, w, "matrix", 16);
      number_array(node, w, "translation", 3);
      number_array(node, w, "rotation", 4);
      number_array(node, w, "scale", 3);
      number_array(node, w, "weights", 0);
      if (find(node, "matrix") && (find(node, "translation") || find(node, "rotation") || find(node, "scale")))
        fail(w, "has both a matrix and translation/rotation/scale");
      string(node, w, "name", false);
      extensions(node, w);
      if (const json* light = extension(node, "KHR_lights_punctual"))
        index(*light, w.in("extensions.KHR_lights_punctual"), "light", light_count_, "light", true);
    }
  }

  // ---- binary data -------------------------------------------------------------------------------
  // A relative uri resolved against the glTF's folder; it must name a regular file (never a
  // directory or a device). Returns the lexically normal path and the file size.
  std::pair<std::string, uint64_t> resolve_file(const Where& w, const std::string& uri) const {
    if (has_uri_scheme(uri) || uri.front() == '/' || uri.front() == '\\')
      fail(w, "uri", shown(uri) + " is not a relative file reference (remote and absolute uris are refused)");
    const auto decoded = percent_decode(uri);
    if (!decoded) fail(w, "uri", shown(uri) + " has a malformed percent escape");
    namespace fs = std::filesystem;
    const fs::path path = (base_dir_.empty() ? fs::path(*decoded) : fs::path(base_dir_) / *decoded).lexically_normal();
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (!fs::exists(status)) fail(w, "uri", shown(uri) + " names a file that does not exist");
    if (!fs::is_regular_file(status)) fail(w, "uri", shown(uri) + " does not name a regular file");
    const uint64_t size = fs::file_size(path, ec);
    if (ec) fail(w, "uri", shown(uri) + " names a file that cannot be read: " + ec.message());
    if (size > kMaxExternalFileBytes) fail(w, "uri", shown(uri) + " names a file larger than 4 GiB");
    return {path.string(), size};
  }

  // Decoded size of a base64 data uri whose media type is one of `mime_types`; nullopt if not a data uri.
  std::optional<uint64_t> data_uri_size(const Where& w, const std::string& uri,
                                        std::initializer_list<const char*> mime_types) const {
    if (uri.rfind("data:", 0) != 0) return std::nullopt;
    const size_t comma = uri.find(',');
    const std::string header = comma == std::string::npos ? "" : uri.substr(5, comma - 5);
    const std::string suffix = ";base64";
    if (header.size() < suffix.size() || header.compare(header.size() - suffix.size(), suffix.size(), suffix) != 0)
      fail(w, "data uri is not base64-encoded");
    const std::string mime = header.substr(0, header.size() - suffix.size());
    bool known = false;
    for (const char* m : mime_types) known = known || mime == m;
    if (!known) fail(w, "data uri media type " + shown(mime) + " is not supported");
    const auto size = base64_decoded_size(uri, comma + 1);
    if (!size) fail(w, "data uri is not valid base64");
    return size;
  }

  void check_buffers() {
    const json& buffers = top_array("buffers");
    for (size_t i = 0; i < buffers.size(); ++i) {
      const json& buffer = buffers[i];
      const Where w{"buffer " + std::to_string(i), ""};
      const uint64_t byte_length = uint64_t(*integer(buffer, w, "byteLength", true, 1));
      const std::string length_text = "byteLength " + std::to_string(byte_length);
      string(buffer, w, "name", false);
      extensions(buffer, w);
      buffer_lengths_.push_back(byte_length);
      const auto uri = string(buffer, w, "uri", false);
      if (!uri || uri->empty()) {
        if (!glb_bin_size_ || i != 0) fail(w, "has no uri (only the first buffer of a .glb file may use its BIN chunk)");
        if (*glb_bin_size_ == 0) fail(w, "has no uri and the .glb file has no BIN chunk");
        if (byte_length > *glb_bin_size_)
          fail(w, length_text + " is larger than the " + std::to_string(*glb_bin_size_) + "-byte BIN chunk");
      } else if (const auto size = data_uri_size(w, *uri, {"application/octet-stream", "application/gltf-buffer"})) {
        if (*size != byte_length)  // tinygltf demands an exact match, as does the glTF validator
          fail(w, "data uri decodes to " + std::to_string(*size) + " bytes, " + length_text);
      } else {
        const auto [path, file_size] = resolve_file(w, *uri);
        if (file_size < byte_length)
          fail(w, "file " + shown(*uri) + " holds " + std::to_string(file_size) + " bytes, " + length_text);
        files_.readable[path] = byte_length;
      }
    }
  }

  void check_buffer_views() {
    const json& views = top_array("bufferViews");
    for (size_t i = 0; i < views.size(); ++i) {
      const json& view = views[i];
      const Where w{"bufferView " + std::to_string(i), ""};
      const uint64_t buffer = uint64_t(*index(view, w, "buffer", buffer_lengths_.size(), "buffer", true));
      const uint64_t offset = uint64_t(integer(view, w, "byteOffset", false).value_or(0));
      const uint64_t length = uint64_t(*integer(view, w, "byteLength", true, 1));
      const auto stride = integer(view, w, "byteStride", false, 4, 252);
      if (stride && *stride % 4 != 0) fail(w, "byteStride", std::to_string(*stride) + " is not a multiple of 4");
      if (const auto target = integer(view, w, "target", false); target && *target != 34962 && *target != 34963)
        fail(w, "target", std::to_string(*target) + " is not 34962 (ARRAY_BUFFER) or 34963 (ELEMENT_ARRAY_BUFFER)");
      string(view, w, "name", false);
      extensions(view, w);
      const uint64_t buffer_length = buffer_lengths_[buffer];
      if (!fits(offset, 1, length, length, buffer_length))
        fail(w, "byteOffset " + std::to_string(offset) + " + byteLength " + std::to_string(length) + " exceeds the " +
                    std::to_string(buffer_length) + " bytes of buffer " + std::to_string(buffer));
      views_.push_back({buffer, offset, length, uint64_t(stride.value_or(0))});
    }
  }

  // ---- accessors ---------------------------------------------------------------------------------
  // `count` elements of `size` bytes at `offset` inside bufferView `view_index`, `stride` apart
  // (0 = tightly packed), aligned to `alignment` bytes.
  void check_view_range(const Where& w, uint64_t view_index, uint64_t offset, uint64_t count, uint64_t size,
                        bool allow_stride, int alignment) const {
    const BufferViewInfo& view = views_[view_index];
    const std::string view_name = "bufferView " + std::to_string(view_index);
    if (view.stride != 0 && !allow_stride) fail(w, "uses " + view_name + ", which must not have a byteStride");
    if (offset % uint64_t(alignment) != 0)
      fail(w, "byteOffset", std::to_string(offset) + " is not a multiple of the component size " + std::to_string(alignment));
    if ((view.offset + offset) % uint64_t(alignment) != 0)
      fail(w, "starts at byte " + std::to_string(view.offset + offset) + " of buffer " + std::to_string(view.buffer) +
                  ", which is not aligned to its component size " + std::to_string(alignment));
    const uint64_t stride = view.stride != 0 ? view.stride : size;
    if (stride < size)
      fail(w, "element size " + std::to_string(size) + " is larger than the byteStride " + std::to_string(stride) +
                  " of " + view_name);
    if (!fits(offset, count, size, stride, view.length))
      fail(w, std::to_string(count) + " elements at byteOffset " + std::to_string(offset) + " run past the end of " +
                  view_name + " (" + std::to_string(view.length) + " bytes)");
  }

  void check_sparse(const json& sparse, const Where& w, const AccessorInfo& accessor, uint64_t element) const {
    const uint64_t count = uint64_t(*integer(sparse, w, "count", true, 1));
    if (count > accessor.count)
      fail(w, "count", std::to_string(count) + " exceeds the accessor count " + std::to_string(accessor.count));
    const Where wi = w.in("indices"), wv = w.in("values");
    const json& indices = *object_member(sparse, w, "indices", true);
    const json& values = *object_member(sparse, w, "values", true);
    const int64_t index_type = *integer(indices, wi, "componentType", true);
    if (index_type != kUnsignedByte && index_type != kUnsignedShort && index_type != kUnsignedInt)
      fail(wi, "componentType", std::to_string(index_type) + " is not UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
    const uint64_t index_view = uint64_t(*index(indices, wi, "bufferView", views_.size(), "bufferView", true));
    const uint64_t value_view = uint64_t(*index(values, wv, "bufferView", views_.size(), "bufferView", true));
    const int index_size = component_size(index_type);
    check_view_range(wi, index_view, uint64_t(integer(indices, wi, "byteOffset", false).value_or(0)), count,
                     uint64_t(index_size), false, index_size);
    check_view_range(wv, value_view, uint64_t(integer(values, wv, "byteOffset", false).value_or(0)), count, element,
                     false, component_size(accessor.component_type));
    extensions(sparse, w);
    extensions(indices, wi);
    extensions(values, wv);
  }

  void check_accessors() {
    const json& accessors = top_array("accessors");
    for (size_t i = 0; i < accessors.size(); ++i) {
      const json& a = accessors[i];
      const Where w{"accessor " + std::to_string(i), ""};
      AccessorInfo info;
      info.view = index(a, w, "bufferView", views_.size(), "bufferView", false).value_or(-1);
      const auto offset = integer(a, w, "byteOffset", false);
      if (offset && info.view < 0) fail(w, "byteOffset", "is set but the accessor has no bufferView");
      info.component_type = *integer(a, w, "componentType", true);
      const int csize = component_size(info.component_type);
      if (csize == 0) fail(w, "componentType", std::to_string(info.component_type) + " is not a glTF componentType");
      boolean(a, w, "normalized");
      info.normalized = find(a, "normalized") && find(a, "normalized")->get<bool>();
      if (info.normalized && (info.component_type == kFloat || info.component_type == kUnsignedInt))
        fail(w, "normalized", "must not be true for FLOAT or UNSIGNED_INT components");
      info.count = uint64_t(*integer(a, w, "count", true, 1));
      info.type = *string(a, w, "type", true);
      const int components = type_components(info.type);
      if (components == 0) fail(w, "type", shown(info.type) + " is not SCALAR, VEC2, VEC3, VEC4, MAT2, MAT3 or MAT4");
      number_array(a, w, "min", size_t(components));
      number_array(a, w, "max", size_t(components));
      string(a, w, "name", false);
      extensions(a, w);
      const uint64_t element = element_size(info.component_type, info.type);
      if (info.view >= 0)
        check_view_range(w, uint64_t(info.view), uint64_t(offset.value_or(0)), info.count, element, true, csize);
      if (const json* sparse = object_member(a, w, "sparse", false)) check_sparse(*sparse, w.in("sparse"), info, element);
      accessors_.push_back(info);
    }
  }

  // ---- meshes ------------------------------------------------------------------------------------
  // Component types the spec allows for the attributes the importer reads (others are not checked).
  void check_attribute_type(const Where& w, const std::string& name, int64_t accessor_index) const {
    const AccessorInfo& a = accessors_[size_t(accessor_index)];
    const std::string what = "attributes." + name + " (accessor " + std::to_string(accessor_index) + ")";
    const bool is_float = a.component_type == kFloat;
    if (name == "POSITION" || name == "NORMAL") {
      if (a.type != "VEC3" || !is_float) fail(w, what + " must be VEC3 FLOAT");
    } else if (name == "TANGENT") {
      if (a.type != "VEC4" || !is_float) fail(w, what + " must be VEC4 FLOAT");
    } else if (name.rfind("TEXCOORD_", 0) == 0) {
      const bool normalized_int =
          a.normalized && (a.component_type == kUnsignedByte || a.component_type == kUnsignedShort);
      if (a.type != "VEC2" || !(is_float || normalized_int))
        fail(w, what + " must be VEC2 of FLOAT or of normalized UNSIGNED_BYTE/UNSIGNED_SHORT");
    }
  }

  void check_primitive(const json& primitive, const Where& w) const {
    const json& attributes = *object_member(primitive, w, "attributes", true);
    const size_t accessor_count = accessors_.size();
    // Every attribute has as many elements as POSITION (or, without POSITION, as the first one).
    std::optional<uint64_t> vertex_count;
    std::string reference;
    if (find(attributes, "POSITION")) {
      const int64_t a = *index(attributes, w.in("attributes"), "POSITION", accessor_count, "accessor", true);
      vertex_count = accessors_[size_t(a)].count;
      reference = "POSITION";
    }
    for (auto it = attributes.begin(); it != attributes.end(); ++it) {
      const int64_t a = *index(attributes, w.in("attributes"), it.key(), accessor_count, "accessor", true);
      check_attribute_type(w, it.key(), a);
      const uint64_t n = accessors_[size_t(a)].count;
      if (!vertex_count) vertex_count = n, reference = it.key();
      if (n != *vertex_count)
        fail(w, "attributes." + it.key() + " (accessor " + std::to_string(a) + ") has " + std::to_string(n) +
                    " elements, " + reference + " has " + std::to_string(*vertex_count));
    }
    const int64_t mode = integer(primitive, w, "mode", false, 0, 6).value_or(kTriangles);
    index(primitive, w, "material", count("materials"), "material", false);
    if (const auto indices = index(primitive, w, "indices", accessor_count, "accessor", false)) {
      const AccessorInfo& a = accessors_[size_t(*indices)];
      const std::string what = "indices (accessor " + std::to_string(*indices) + ")";
      if (a.type != "SCALAR" || (a.component_type != kUnsignedByte && a.component_type != kUnsignedShort &&
                                 a.component_type != kUnsignedInt))
        fail(w, what + " must be SCALAR UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
      if (a.view >= 0 && views_[size_t(a.view)].stride != 0)
        fail(w, what + " use bufferView " + std::to_string(a.view) + ", which must not have a byteStride");
      if (mode == kTriangles && a.count % 3 != 0)
        fail(w, what + " has " + std::to_string(a.count) + " indices; TRIANGLES needs a multiple of 3");
    } else if (mode == kTriangles && vertex_count && *vertex_count % 3 != 0) {
      fail(w, "has " + std::to_string(*vertex_count) + " vertices and no indices; TRIANGLES needs a multiple of 3");
    }
    if (const json* targets = array_member(primitive, w, "targets", false)) {
      for (size_t t = 0; t < targets->size(); ++t) {
        const Where wt = w.in("targets[" + std::to_string(t) + "]");
        if (!(*targets)[t].is_object()) fail(wt, "must be a JSON object, not " + describe((*targets)[t]));
        for (auto it = (*targets)[t].begin(); it != (*targets)[t].end(); ++it)
          index((*targets)[t], wt, it.key(), accessor_count, "accessor", true);
      }
    }
    extensions(primitive, w);
  }

  void check_meshes() const {
    const json& meshes = top_array("meshes");
    for (size_t m = 0; m < meshes.size(); ++m) {
      const Where w{"mesh " + std::to_string(m), ""};
      const json& primitives = *array_member(meshes[m], w, "primitives", true);
      if (primitives.empty()) fail(w, "primitives", "is empty (a mesh needs at least one primitive)");
      number_array(meshes[m], w, "weights", 0);
      string(meshes[m], w, "name", false);
      extensions(meshes[m], w);
      for (size_t p = 0; p < primitives.size(); ++p) {
        const Where wp{"mesh " + std::to_string(m) + " primitive " + std::to_string(p), ""};
        if (!primitives[p].is_object()) fail(wp, "must be a JSON object, not " + describe(primitives[p]));
        check_primitive(primitives[p], wp);
      }
    }
  }

  // ---- images, samplers, textures, materials -----------------------------------------------------
  void check_images() {
    const json& images = top_array("images");
    for (size_t i = 0; i < images.size(); ++i) {
      const json& image = images[i];
      const Where w{"image " + std::to_string(i), ""};
      const auto uri = string(image, w, "uri", false);
      const auto view = index(image, w, "bufferView", views_.size(), "bufferView", false);
      const auto mime = string(image, w, "mimeType", false);
      string(image, w, "name", false);
      extensions(image, w);
      if (uri && view) fail(w, "has both a uri and a bufferView");
      if (!uri && !view) fail(w, "has neither a uri nor a bufferView");
      if (view && !mime) fail(w, "mimeType", "is required with a bufferView");
      if (uri && uri->empty()) fail(w, "uri", "is empty");
      if (uri && !data_uri_size(w, *uri, {"image/png", "image/jpeg", "image/bmp", "image/gif"})) {
        const auto [path, size] = resolve_file(w, *uri);
        files_.readable[path] = size;
      }
    }
  }

  void check_samplers() const {
    const json& samplers = top_array("samplers");
    for (size_t i = 0; i < samplers.size(); ++i) {
      const Where w{"sampler " + std::to_string(i), ""};
      const auto check_enum = [&](const char* key, std::initializer_list<int64_t> allowed) {
        const auto v = integer(samplers[i], w, key, false);
        if (v && std::find(allowed.begin(), allowed.end(), *v) == allowed.end())
          fail(w, key, std::to_string(*v) + " is not a valid value");
      };
      check_enum("magFilter", {9728, 9729});
      check_enum("minFilter", {9728, 9729, 9984, 9985, 9986, 9987});
      check_enum("wrapS", {33071, 33648, 10497});
      check_enum("wrapT", {33071, 33648, 10497});
      string(samplers[i], w, "name", false);
      extensions(samplers[i], w);
    }
  }

  void check_textures() const {
    const json& textures = top_array("textures");
    for (size_t i = 0; i < textures.size(); ++i) {
      const Where w{"texture " + std::to_string(i), ""};
      index(textures[i], w, "sampler", count("samplers"), "sampler", false);
      index(textures[i], w, "source", count("images"), "image", false);
      string(textures[i], w, "name", false);
      extensions(textures[i], w);
    }
  }

  void texture_info(const json& owner, const Where& w, const std::string& key) const {
    const json* info = object_member(owner, w, key, false);
    if (!info) return;
    const Where wi = w.in(key);
    index(*info, wi, "index", count("textures"), "texture", true);
    integer(*info, wi, "texCoord", false);
    number(*info, wi, "scale", false);
    number(*info, wi, "strength", false);
    extensions(*info, wi);
    if (const json* t = extension(*info, "KHR_texture_transform")) {
      const Where wt = wi.in("extensions.KHR_texture_transform");
      number_array(*t, wt, "offset", 2);
      number_array(*t, wt, "scale", 2);
      number(*t, wt, "rotation", false);
      integer(*t, wt, "texCoord", false);
    }
  }

  void check_materials() const {
    const json& materials = top_array("materials");
    for (size_t i = 0; i < materials.size(); ++i) {
      const json& material = materials[i];
      const Where w{"material " + std::to_string(i), ""};
      if (const json* pbr = object_member(material, w, "pbrMetallicRoughness", false)) {
        const Where wp = w.in("pbrMetallicRoughness");
        number_array(*pbr, wp, "baseColorFactor", 4);
        texture_info(*pbr, wp, "baseColorTexture");
        number(*pbr, wp, "metallicFactor", false);
        number(*pbr, wp, "roughnessFactor", false);
        texture_info(*pbr, wp, "metallicRoughnessTexture");
        extensions(*pbr, wp);
      }
      texture_info(material, w, "normalTexture");
      texture_info(material, w, "occlusionTexture");
      texture_info(material, w, "emissiveTexture");
      number_array(material, w, "emissiveFactor", 3);
      if (const auto mode = string(material, w, "alphaMode", false); mode && *mode != "OPAQUE" && *mode != "MASK" &&
                                                                   *mode != "BLEND")
        fail(w, "alphaMode", shown(*mode) + " is not OPAQUE, MASK or BLEND");
      number(material, w, "alphaCutoff", false, 0.0);
      boolean(material, w, "doubleSided");
      string(material, w, "name", false);
      extensions(material, w);
      if (const json* strength = extension(material, "KHR_materials_emissive_strength"))
        number(*strength, w.in("extensions.KHR_materials_emissive_strength"), "emissiveStrength", false, 0.0);
    }
  }

  const json& doc_;
  const std::string& file_;
  const std::string& base_dir_;
  std::optional<uint64_t> glb_bin_size_;
  size_t light_count_ = 0;
  std::vector<uint64_t> buffer_lengths_;
  std::vector<BufferViewInfo> views_;
  std::vector<AccessorInfo> accessors_;
  GltfExternalFiles files_;
};

}  // namespace

GltfExternalFiles validate_gltf_json(const nlohmann::json& document, const std::string& file,
                                     const std::string& base_dir, std::optional<uint64_t> glb_bin_size) {
  return Validator(document, file, base_dir, glb_bin_size).run();
}

}  // namespace exitance
