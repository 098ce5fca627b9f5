// glTF node transforms in one compiled copy: the importer (bake/import/gltf_import.cpp) flattens
// the node hierarchy with these functions and the runtime's scene edits (refresh/scene_edits.h)
// recompute world matrices, instance geometry and light placement with the same ones, so an edit
// gives what importing the edited glTF would (bit for bit for the matrices).
// Matrices are column-major doubles (Matrix4d, scene.h), as glTF stores them.
#pragma once
#include <array>
#include <optional>
#include <vector>

#include "exitance/runtime/matrix4d.h"
#include "exitance/runtime/scene.h"

namespace exitance {

// multiply(a, b) and trs_matrix(t, r, s): exitance/runtime/matrix4d.h (header-only).

// The node's local transform: `matrix` when has_matrix, else trs_matrix of its parts.
Matrix4d local_matrix(const SceneNode& node);

// World matrix of every node of the default scene (std::nullopt for nodes outside it): the
// parent's world times the local matrix, the identity standing for a root's parent (as the
// importer multiplies). Throws std::invalid_argument for a parent index out of range or a cycle.
std::vector<std::optional<Matrix4d>> node_world_matrices(const Scene& scene);

// m * (p, 1) and the 3x3 cofactor matrix of m times n (det * inverse-transpose: a normal's
// direction for det > 0, flipped for a mirroring m), each rounded to float once.
Vec3 transform_point(const Matrix4d& m, Vec3 p);
Vec3 transform_normal(const Matrix4d& m, Vec3 n);
double determinant3(const Matrix4d& m);

// Inverse of an affine matrix (bottom row 0 0 0 1); std::nullopt when the 3x3 part is singular or
// the result is not finite.
std::optional<Matrix4d> affine_inverse(const Matrix4d& m);

// A punctual light at the origin of `world`, shining along its -Z: position and unit direction as
// the importer places KHR_lights_punctual lights. False (light unchanged) when the transform
// collapses the direction.
bool place_light(const Matrix4d& world, PunctualLight& light);

}  // namespace exitance
