// Which node, light or material an edit names (scene_edits.h): a name must match exactly one.
#pragma once
#include <cstdint>
#include <string>

#include "exitance/runtime/refresh/scene_edits.h"

namespace exitance::refresh {

// Throw SceneEditError naming `where` for no match, several matches (how many, and their indices:
// use one) or an index out of range.
uint32_t resolve_node(const Scene& scene, const EditTarget& target, const std::string& where);
uint32_t resolve_light(const Scene& scene, const EditTarget& target, const std::string& where);
uint32_t resolve_material(const Scene& scene, const EditTarget& target, const std::string& where);

}  // namespace exitance::refresh
