#include "edit_checks.h"

#include <charconv>
#include <cmath>
#include <numbers>

namespace exitance::refresh {
namespace {

template <typename T>
void check_finite(const std::string& where, const char* field, T v) {
  if (!std::isfinite(v)) fail(where, std::string(field) + ": " + number_text(v) + " is not a finite number");
}

void check_unit_interval(const std::string& where, const char* field, const std::array<float, 3>& c) {
  for (float v : c) {
    check_finite(where, field, v);
    if (v < 0 || v > 1)
      fail(where, std::string(field) + ": " + number_text(v) + " is outside [0, 1] (glTF colours; scale with " +
                      (std::string(field) == "color" ? "intensity" : "emissiveStrength") + ")");
  }
}

void check_non_negative(const std::string& where, const char* field, float v) {
  check_finite(where, field, v);
  if (v < 0) fail(where, std::string(field) + ": " + number_text(v) + " is negative");
}

void check_cone_angle(const std::string& where, const char* field, double v) {
  check_finite(where, field, v);
  if (v < 0 || v > std::numbers::pi / 2 + 1e-9)
    fail(where, std::string(field) + ": " + number_text(v) + " is outside [0, pi/2] (radians)");
}

void check_node(const NodeEdit& e, const std::string& where) {
  if (!e.translation && !e.rotation && !e.scale) fail(where, "changes nothing (give translation, rotation or scale)");
  if (e.translation)
    for (double v : *e.translation) check_finite(where, "translation", v);
  if (e.rotation) {
    double length2 = 0;
    for (double v : *e.rotation) check_finite(where, "rotation", v), length2 += v * v;
    const double length = std::sqrt(length2);
    // A unit quaternion as glTF requires; a length far from 1 is more likely Euler angles or a typo.
    if (!(std::fabs(length - 1.0) <= 1e-3))
      fail(where, "rotation: length " + number_text(length) + " is not 1 (a unit quaternion [x, y, z, w])");
  }
  if (e.scale)
    for (size_t i = 0; i < 3; ++i) {
      check_finite(where, "scale", (*e.scale)[i]);
      if ((*e.scale)[i] == 0)
        fail(where, "scale: component " + std::to_string(i) + " is 0 (the transform would not be invertible)");
    }
}

void check_light(const LightEdit& e, const std::string& where) {
  if (!e.color && !e.intensity && !e.inner_cone_angle && !e.outer_cone_angle)
    fail(where, "changes nothing (give color, intensity, innerConeAngle or outerConeAngle)");
  if (e.color) check_unit_interval(where, "color", *e.color);
  if (e.intensity) check_non_negative(where, "intensity", *e.intensity);
  if (e.inner_cone_angle) check_cone_angle(where, "innerConeAngle", *e.inner_cone_angle);
  if (e.outer_cone_angle) check_cone_angle(where, "outerConeAngle", *e.outer_cone_angle);
  if (e.inner_cone_angle && e.outer_cone_angle && !(*e.inner_cone_angle < *e.outer_cone_angle))
    fail(where, "innerConeAngle: " + number_text(*e.inner_cone_angle) + " is not below outerConeAngle " +
                    number_text(*e.outer_cone_angle));
}

void check_material(const MaterialEdit& e, const std::string& where) {
  if (!e.emissive_factor && !e.emissive_strength)
    fail(where, "changes nothing (give emissiveFactor or emissiveStrength)");
  if (e.emissive_factor) check_unit_interval(where, "emissiveFactor", *e.emissive_factor);
  if (e.emissive_strength) check_non_negative(where, "emissiveStrength", *e.emissive_strength);
}

}  // namespace

template <typename T>
std::string shortest_text(T v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), v);
  return std::string(buffer, result.ptr);
}

std::string number_text(double v) { return shortest_text(v); }
std::string number_text(float v) { return shortest_text(v); }

std::string target_label(const char* kind, const EditTarget& target) {
  if (target.index) return std::string(kind) + " " + std::to_string(*target.index);
  return std::string(kind) + " \"" + target.name + "\"";
}

void fail(const std::string& where, const std::string& what) { throw SceneEditError(where + ": " + what); }

void check_edit_values(const SceneEdit& edit, const std::string& where) {
  if (const auto* node = std::get_if<NodeEdit>(&edit.change)) check_node(*node, where);
  if (const auto* light = std::get_if<LightEdit>(&edit.change)) check_light(*light, where);
  if (const auto* material = std::get_if<MaterialEdit>(&edit.change)) check_material(*material, where);
  if (const auto* sky = std::get_if<SkyEdit>(&edit.change))
    for (float v : sky->color) check_non_negative(where, "sky", v);
}

}  // namespace exitance::refresh
