// Edits of a baked scene (issue 10, docs/edits.md): node transforms, light colour / intensity /
// cone angles, material emission, sky colour, named as in the glTF, applied atomically to the
// scene restored from scene.bin (geometry, lights, texel G-buffer, BVH).
//
// Use (exitance-relight, the refresh API):
//   std::vector<SceneEdit> edits = parse_scene_edits(text, "edits.json");   // or build them in code
//   EditEffects effects = apply_scene_edits(persisted, edits);             // all or nothing
//   update_lighting_scene(lighting, std::make_shared<const Scene>(persisted.scene), effects);
//   if (effects.geometry_changed()) integrator.update_geometry(lighting);
//   else { if (!effects.materials.empty()) integrator.update_materials(lighting);
//          if (!effects.lights.empty() || effects.sky) integrator.update_lights(lighting); }
//   ...and bake persisted.gbuffer again (texels of moved instances moved with them).
// (A LightingScene built afresh from the edited PersistedScene, build_lighting_scene(scene,
// to_bvh4(persisted.bvh)), is the same: apply_scene_edits refits persisted.bvh too.)
//
// Values are absolute (not increments), in glTF's units. The scene keeps only the products
// colour x intensity (lights) and emissiveFactor x emissiveStrength (materials), so an edit that
// gives one part takes the other from the current product:
//   light:    intensity = the product's largest component, colour = product / intensity (white
//             when the product is black);
//   material: strength = max(1, the product's largest component), factor = product / strength
//             (so a product within [0, 1] is the factor itself, glTF's default strength being 1).
#pragma once
#include <functional>
#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "exitance/runtime/core/lighting_scene.h"
#include "exitance/runtime/scene_file_conversion.h"
#include "exitance/runtime/world_box.h"

namespace exitance {

// One line naming the file, the edit and the problem, e.g.
//   edits.json: edits[2] (light "Lamp"): intensity: -1 is negative
class SceneEditError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What an edit addresses: a glTF name that must match exactly one node / light / material, or an
// index into the glTF's list (Scene::nodes, Scene::lights by scene order, Scene::materials).
struct EditTarget {
  std::string name;
  std::optional<uint32_t> index;  // set: the index, `name` unused
};

// Replaces the given parts of the node's local transform (a node given as `matrix` is decomposed
// into translation, rotation and scale first; a translation-only edit replaces the matrix's
// translation column). Moves the mesh instances, lights and child nodes under the node.
struct NodeEdit {
  EditTarget node;
  std::optional<std::array<double, 3>> translation;
  std::optional<std::array<double, 4>> rotation;  // unit quaternion x, y, z, w
  std::optional<std::array<double, 3>> scale;     // every component non-zero
};

struct LightEdit {
  EditTarget light;
  std::optional<std::array<float, 3>> color;  // linear, each in [0, 1]
  std::optional<float> intensity;             // >= 0: W/sr (point, spot) or W/m^2 (directional)
  std::optional<double> inner_cone_angle;     // radians, spot lights only: 0 <= inner < outer <= pi/2
  std::optional<double> outer_cone_angle;
};

struct MaterialEdit {
  EditTarget material;
  std::optional<std::array<float, 3>> emissive_factor;  // each in [0, 1]
  std::optional<float> emissive_strength;               // >= 0 (KHR_materials_emissive_strength)
};

// A constant sky radiance (replaces an environment map).
struct SkyEdit {
  std::array<float, 3> color{0, 0, 0};
};

struct SceneEdit {
  std::variant<NodeEdit, LightEdit, MaterialEdit, SkyEdit> change;
  // Prefix of its error messages, e.g. `edits.json: edits[2] (light "Lamp")`; parse_scene_edits
  // sets it; when empty, apply_scene_edits says `edits[i] (node "Box")`.
  std::string where;
};

// Parses `{"edits": [...]}` (docs/edits.md, docs/edits.schema.json) and checks every value that
// needs no scene: finite numbers, non-negative intensity and strength, colours in [0, 1], cone
// angles in [0, pi/2], a rotation whose length is within 1e-3 of 1, no zero scale, no unknown key.
// Throws SceneEditError, its message beginning with `name_for_errors`.
std::vector<SceneEdit> parse_scene_edits(std::string_view json_text, const std::string& name_for_errors);

// What apply_scene_edits changed, so the caller updates only that (indices ascending, unique).
struct EditEffects {
  std::vector<uint32_t> lights;           // Scene::lights whose record changed (edited or moved)
  std::vector<uint32_t> materials;        // Scene::materials edited
  bool sky = false;
  std::vector<uint32_t> moved_instances;  // Scene::instances whose world transform changed
  size_t moved_texels = 0;                // live texels of those instances, moved with them
  bool geometry_changed() const { return !moved_instances.empty(); }
};

// Applies `edits` in order (a later edit of the same thing wins), all or nothing: everything is
// validated and computed on copies and `scene` is assigned only when every edit succeeded
// (strong guarantee; it is untouched when this throws SceneEditError). Per moved instance: world
// matrix recomposed from the nodes (node_transform.h, as the importer does), positions moved by
// new_world * old_world^-1 and normals by its inverse transpose, the texels of the instance
// re-derived from their triangle as the rasterizer does (texel_surface.h; a texel the unocclude
// step had pushed keeps its offset, moved rigidly), their world texel size recomputed; lights
// under a moved node are placed again; the BVH is refit (bvh4_refit.h). A no-op edit leaves the
// scene bit for bit as it was. Errors: a name matching no or several targets, an index out of
// range, a transform that is singular, not finite, collapses a light's direction or a triangle,
// a matrix node that does not decompose (shear), cone angles on a non-spot light, and what
// parse_scene_edits checks (edits built in code are checked the same way).
EditEffects apply_scene_edits(PersistedScene& scene, const std::vector<SceneEdit>& edits);

// Instance k's live texels: texels[start[k] .. start[k + 1]) (ascending), so an edit that moves
// an instance finds its texels without a pass over the G-buffer. Texels never change instance.
struct InstanceTexels {
  InstanceTexels() = default;
  InstanceTexels(const TexelGBuffer& gbuffer, size_t instance_count);
  std::vector<uint32_t> start, texels;
};

// What apply_scene_edits_in_place changed, for the caller to bring the BVH, the lighting scene, the
// device and its own indices along without a pass over the scene.
struct InPlaceEdits {
  EditEffects effects;
  std::vector<uint32_t> moved_triangles;            // ascending
  std::vector<Vec3> moved_triangles_before;         // their 3 vertices each, as before the edits
  std::vector<WorldBox> moved_boxes_before, moved_boxes_after;  // per effects.moved_instances
  std::vector<Matrix4d> moved_deltas;               // per effects.moved_instances: world after * world before^-1
  std::vector<uint32_t> moved_texels;               // ascending: the G-buffer texels rewritten
  // With `defer_texels`: rewrites moved_texels in the committed scene's G-buffer (reads the scene,
  // the atlas and those texels, writes those texels only; cannot throw), for the caller to run
  // beside its other work (the BVH refit); empty when nothing is left to do.
  std::function<void()> move_texels;
};

// apply_scene_edits without copying the scene (the runtime's edit path): every edit is validated and
// computed on copies of the scene's small parts (nodes, instances, lights, materials, the sky's
// colour) and of the moved instances' triangles, then committed in place, with the same edit
// functions, so the scene, its texels and what the result lists are apply_scene_edits' bit for bit.
// `persisted.bvh` is left as it was: the caller refits it over `moved_triangles` (refit_bvh4_moved;
// RefreshSession does, on its lighting scene's BVH, and copies the changed nodes back).
// `by_instance` (may be null: a pass over the texels) must be built on this G-buffer. Throws
// SceneEditError as apply_scene_edits does, `persisted` untouched. `defer_texels`: the moved
// texels are rewritten by the caller, through the result's move_texels, before it reads them.
InPlaceEdits apply_scene_edits_in_place(PersistedScene& persisted, const std::vector<SceneEdit>& edits,
                                        const InstanceTexels* by_instance, bool defer_texels = false);

// Brings `lighting`, built on the scene before apply_scene_edits, to `edited` (the scene after):
// set_geometry (lighting_scene.h: everything re-derived, BVH refit) when geometry moved, else
// set_material / set_punctual_light for what `effects` lists and the sky. The result equals
// build_lighting_scene(edited, the refit BVH). Strong guarantee (works on a copy); throws
// std::invalid_argument when `edited` does not have `lighting`'s triangles, materials and lights.
void update_lighting_scene(LightingScene& lighting, std::shared_ptr<const Scene> edited, const EditEffects& effects);

}  // namespace exitance
