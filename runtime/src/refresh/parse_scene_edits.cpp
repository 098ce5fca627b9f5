// EDITS.json -> SceneEdit (docs/edits.md): the document's shape here, the values' rules in
// edit_checks.cpp. Unknown keys are errors: a misspelt field must not be silently ignored.
#include <algorithm>

#include <nlohmann/json.hpp>

#include "edit_checks.h"
#include "exitance/runtime/refresh/scene_edits.h"

namespace exitance {
namespace {

using json = nlohmann::json;
using refresh::fail;

// Where the edit's own keys are read: its label and the object.
struct EditReader {
  const json& object;
  std::string where;

  double number(const char* key) const {
    const json& v = object.at(key);
    if (!v.is_number()) fail(where, std::string(key) + ": must be a number");
    return v.get<double>();
  }
  template <size_t N>
  std::array<double, N> numbers(const char* key) const {
    const json& v = object.at(key);
    if (!v.is_array() || v.size() != N || !std::all_of(v.begin(), v.end(), [](const json& x) { return x.is_number(); }))
      fail(where, std::string(key) + ": must be an array of " + std::to_string(N) + " numbers");
    std::array<double, N> out{};
    for (size_t i = 0; i < N; ++i) out[i] = v[i].get<double>();
    return out;
  }
  std::array<float, 3> color(const char* key) const {
    const std::array<double, 3> c = numbers<3>(key);
    return {float(c[0]), float(c[1]), float(c[2])};
  }
  bool has(const char* key) const { return object.contains(key); }
  void only(std::initializer_list<const char*> allowed) const {
    for (const auto& item : object.items()) {
      const std::string& key = item.key();  // a plain name: clang 14 cannot capture structured bindings
      if (std::none_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; })) {
        std::string list;
        for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
        fail(where, "unknown key \"" + key + "\" (this edit takes " + list + ")");
      }
    }
  }
};

EditTarget target(const json& v, const std::string& where, const char* kind) {
  EditTarget t;
  if (v.is_string()) t.name = v.get<std::string>();
  else if (v.is_number_unsigned() && v.get<uint64_t>() <= UINT32_MAX) t.index = uint32_t(v.get<uint64_t>());
  else fail(where, std::string("\"") + kind + "\" must be a name (string) or an index (integer >= 0)");
  return t;
}

SceneEdit parse_edit(const json& object, const std::string& where_prefix) {
  if (!object.is_object()) fail(where_prefix, "must be an object");
  const char* kinds[] = {"node", "light", "material", "sky"};
  const char* kind = nullptr;
  for (const char* k : kinds)
    if (object.contains(k)) {
      if (kind) fail(where_prefix, std::string("has both \"") + kind + "\" and \"" + k + "\" (one thing per edit)");
      kind = k;
    }
  if (!kind) fail(where_prefix, "names nothing to edit (give \"node\", \"light\", \"material\" or \"sky\")");
  SceneEdit edit;
  const std::string_view k = kind;
  if (k == "sky") {
    edit.where = where_prefix + " (sky)";
    const EditReader r{object, edit.where};
    r.only({"sky"});
    edit.change = SkyEdit{r.color("sky")};
    return edit;
  }
  EditTarget t = target(object.at(kind), where_prefix, kind);
  edit.where = where_prefix + " (" + refresh::target_label(kind, t) + ")";
  const EditReader r{object, edit.where};
  if (k == "node") {
    r.only({"node", "translation", "rotation", "scale"});
    NodeEdit e;
    e.node = std::move(t);
    if (r.has("translation")) e.translation = r.numbers<3>("translation");
    if (r.has("rotation")) e.rotation = r.numbers<4>("rotation");
    if (r.has("scale")) e.scale = r.numbers<3>("scale");
    edit.change = std::move(e);
  } else if (k == "light") {
    r.only({"light", "color", "intensity", "innerConeAngle", "outerConeAngle"});
    LightEdit e;
    e.light = std::move(t);
    if (r.has("color")) e.color = r.color("color");
    if (r.has("intensity")) e.intensity = float(r.number("intensity"));
    if (r.has("innerConeAngle")) e.inner_cone_angle = r.number("innerConeAngle");
    if (r.has("outerConeAngle")) e.outer_cone_angle = r.number("outerConeAngle");
    edit.change = std::move(e);
  } else {
    r.only({"material", "emissiveFactor", "emissiveStrength"});
    MaterialEdit e;
    e.material = std::move(t);
    if (r.has("emissiveFactor")) e.emissive_factor = r.color("emissiveFactor");
    if (r.has("emissiveStrength")) e.emissive_strength = float(r.number("emissiveStrength"));
    edit.change = std::move(e);
  }
  return edit;
}

}  // namespace

std::vector<SceneEdit> parse_scene_edits(std::string_view json_text, const std::string& name_for_errors) {
  json document;
  try {
    document = json::parse(json_text);
  } catch (const json::exception& e) {
    // nlohmann's message: "[json.exception.parse_error.101] parse error at line 1, column 3: ...".
    std::string what = e.what();
    if (const size_t bracket = what.find("] "); what.starts_with("[json.exception.") && bracket != std::string::npos)
      what = what.substr(bracket + 2);
    fail(name_for_errors, "not valid JSON: " + what);
  }
  if (!document.is_object() || !document.contains("edits"))
    fail(name_for_errors, "must be an object {\"edits\": [...]}");
  for (const auto& [key, value] : document.items()) {
    (void)value;
    if (key != "edits") fail(name_for_errors, "unknown key \"" + key + "\" (the document takes only \"edits\")");
  }
  const json& list = document.at("edits");
  if (!list.is_array()) fail(name_for_errors, "\"edits\" must be an array");
  std::vector<SceneEdit> edits;
  for (size_t i = 0; i < list.size(); ++i) {
    SceneEdit edit = parse_edit(list[i], name_for_errors + ": edits[" + std::to_string(i) + "]");
    refresh::check_edit_values(edit, edit.where);
    edits.push_back(std::move(edit));
  }
  return edits;
}

}  // namespace exitance
