#include "edit_targets.h"

#include "edit_checks.h"

namespace exitance::refresh {
namespace {

template <typename T>
uint32_t resolve(const std::vector<T>& items, const EditTarget& target, const std::string& where, const char* kind,
                 const char* plural) {
  if (target.index) {
    if (*target.index >= items.size())
      fail(where, std::string(kind) + " " + std::to_string(*target.index) + " does not exist (the scene has " +
                      std::to_string(items.size()) + " " + plural + ")");
    return *target.index;
  }
  std::vector<uint32_t> matches;
  for (size_t i = 0; i < items.size(); ++i)
    if (items[i].name == target.name) matches.push_back(uint32_t(i));
  if (matches.empty()) fail(where, std::string("no ") + kind + " is named \"" + target.name + "\"");
  if (matches.size() > 1) {
    std::string list;
    for (size_t i = 0; i < matches.size() && i < 8; ++i) list += (i ? ", " : "") + std::to_string(matches[i]);
    if (matches.size() > 8) list += ", ...";
    fail(where, std::to_string(matches.size()) + " " + plural + " are named \"" + target.name + "\" (" + plural + " " +
                    list + "); give the index of one instead of the name");
  }
  return matches[0];
}

}  // namespace

uint32_t resolve_node(const Scene& scene, const EditTarget& target, const std::string& where) {
  return resolve(scene.nodes, target, where, "node", "nodes");
}
uint32_t resolve_light(const Scene& scene, const EditTarget& target, const std::string& where) {
  return resolve(scene.lights, target, where, "light", "lights");
}
uint32_t resolve_material(const Scene& scene, const EditTarget& target, const std::string& where) {
  return resolve(scene.materials, target, where, "material", "materials");
}

}  // namespace exitance::refresh
