// Shared by the edits' parser and their application (scene_edits.h): the one-line messages and
// the checks of an edit's values that need no scene, so edits built in code are held to the same
// rules as parsed ones.
#pragma once
#include <string>

#include "exitance/runtime/refresh/scene_edits.h"

namespace exitance::refresh {

// `v` as a message shows it: shortest round-trip form ("-1", "0.25", "nan", "inf").
std::string number_text(double v);
std::string number_text(float v);  // a float's own shortest form ("0.1", not its double expansion)

// `node "Box"`, `light 3`, `sky`: the part of an edit's label in parentheses.
std::string target_label(const char* kind, const EditTarget& target);

// Throws SceneEditError("<where>: <what>").
[[noreturn]] void fail(const std::string& where, const std::string& what);

// Finite numbers; colours in [0, 1]; intensity, strength and sky >= 0; cone angles in [0, pi/2]
// with inner < outer when both are given; a rotation of length 1 +- 1e-3; no zero scale; an edit
// that changes something.
void check_edit_values(const SceneEdit& edit, const std::string& where);

}  // namespace exitance::refresh
