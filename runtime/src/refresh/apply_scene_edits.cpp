// apply_scene_edits (scene_edits.h): each edit on a copy of the scene, node transforms last
// (moved_instances.h), then one commit that cannot throw.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <set>

#include "edit_checks.h"
#include "edit_targets.h"
#include "exitance/runtime/core/bvh4_refit.h"
#include "moved_instances.h"
#include "exitance/runtime/core/grouped_indices.h"
#include "exitance/runtime/core/parallel_chunks.h"
#include "exitance/runtime/world_box.h"

namespace exitance {
namespace {

using refresh::fail;
using refresh::number_text;

float largest(Vec3 v) { return std::max({v.x, v.y, v.z}); }
Vec3 to_vec3(const std::array<float, 3>& c) { return {c[0], c[1], c[2]}; }

// The scene keeps colour x intensity; the parts an edit does not give come from that product
// (scene_edits.h): intensity = its largest component, colour = product / intensity.
void edit_light(PunctualLight& light, const LightEdit& e, const std::string& where) {
  const float current_intensity = largest(light.intensity);
  const Vec3 current_color = current_intensity > 0 ? light.intensity / current_intensity : Vec3{1, 1, 1};
  const Vec3 color = e.color ? to_vec3(*e.color) : current_color;
  const float intensity = e.intensity ? *e.intensity : current_intensity;
  if (e.color || e.intensity) light.intensity = color * intensity;
  if (!is_finite(light.intensity)) fail(where, "color x intensity is not finite as a float");
  if (e.inner_cone_angle || e.outer_cone_angle) {
    if (light.type != PunctualLight::Type::Spot)
      fail(where, std::string(e.inner_cone_angle ? "innerConeAngle" : "outerConeAngle") + ": light \"" + light.name +
                      "\" is not a spot light");
    const double inner = e.inner_cone_angle ? *e.inner_cone_angle : std::acos(std::clamp(double(light.cos_inner), -1.0, 1.0));
    const double outer = e.outer_cone_angle ? *e.outer_cone_angle : std::acos(std::clamp(double(light.cos_outer), -1.0, 1.0));
    if (!(inner < outer))
      fail(where, std::string(e.inner_cone_angle ? "innerConeAngle" : "outerConeAngle") + ": inner " +
                      number_text(float(inner)) + " is not below outer " + number_text(float(outer)) +
                      (e.inner_cone_angle && e.outer_cone_angle ? "" : " (the other angle as baked)"));
    light.cos_inner = float(std::cos(inner));
    light.cos_outer = float(std::cos(outer));
  }
}

// emissiveFactor x emissiveStrength; strength = max(1, the product's largest component).
void edit_material(Material& material, const MaterialEdit& e, const std::string& where) {
  const float current_strength = std::max(1.0f, largest(material.emission));
  const Vec3 factor = e.emissive_factor ? to_vec3(*e.emissive_factor) : material.emission / current_strength;
  const float strength = e.emissive_strength ? *e.emissive_strength : current_strength;
  material.emission = factor * strength;
  if (!is_finite(material.emission)) fail(where, "emissiveFactor x emissiveStrength is not finite as a float");
}

// A 3x3 rotation (columns, orthonormal, det +1) as a unit quaternion x, y, z, w (Shepperd).
std::array<double, 4> quaternion_of(const double r[3][3]) {  // r[column][row]
  const double m00 = r[0][0], m11 = r[1][1], m22 = r[2][2];
  const double m01 = r[1][0], m10 = r[0][1], m02 = r[2][0], m20 = r[0][2], m12 = r[2][1], m21 = r[1][2];
  const double trace = m00 + m11 + m22;
  double x, y, z, w;
  if (trace > 0) {
    const double s = 2 * std::sqrt(1 + trace);
    w = s / 4, x = (m21 - m12) / s, y = (m02 - m20) / s, z = (m10 - m01) / s;
  } else if (m00 > m11 && m00 > m22) {
    const double s = 2 * std::sqrt(1 + m00 - m11 - m22);
    w = (m21 - m12) / s, x = s / 4, y = (m01 + m10) / s, z = (m02 + m20) / s;
  } else if (m11 > m22) {
    const double s = 2 * std::sqrt(1 + m11 - m00 - m22);
    w = (m02 - m20) / s, x = (m01 + m10) / s, y = s / 4, z = (m12 + m21) / s;
  } else {
    const double s = 2 * std::sqrt(1 + m22 - m00 - m11);
    w = (m10 - m01) / s, x = (m02 + m20) / s, y = (m12 + m21) / s, z = s / 4;
  }
  return {x, y, z, w};
}

// A `matrix` node as translation, rotation, scale (glTF: the matrix must decompose into them).
void decompose_matrix(SceneNode& node, const std::string& where) {
  const Matrix4d& m = node.matrix;
  if (m[3] != 0 || m[7] != 0 || m[11] != 0 || m[15] != 1) fail(where, "the node's matrix is not affine (bottom row 0 0 0 1)");
  double r[3][3], scale[3];
  for (int c = 0; c < 3; ++c) {
    scale[c] = std::sqrt(m[size_t(4 * c)] * m[size_t(4 * c)] + m[size_t(4 * c + 1)] * m[size_t(4 * c + 1)] +
                         m[size_t(4 * c + 2)] * m[size_t(4 * c + 2)]);
    if (!(scale[c] > 0) || !std::isfinite(scale[c])) fail(where, "the node's matrix is singular");
  }
  const double det = m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
                     m[8] * (m[1] * m[6] - m[5] * m[2]);
  if (det < 0) scale[0] = -scale[0];  // a mirror: one negative scale keeps the rotation proper
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row) r[c][row] = m[size_t(4 * c + row)] / scale[c];
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b) {
      const double d = r[a][0] * r[b][0] + r[a][1] * r[b][1] + r[a][2] * r[b][2];
      // Matrices written with float precision are orthogonal to ~1e-7; more is shear.
      if (std::fabs(d) > 1e-6)
        fail(where, "the node's matrix has shear (columns " + std::to_string(a) + " and " + std::to_string(b) +
                        " are not orthogonal), so it has no translation/rotation/scale to replace");
    }
  node.translation = {m[12], m[13], m[14]};
  node.rotation = quaternion_of(r);
  node.scale = {scale[0], scale[1], scale[2]};
  node.matrix = kIdentityMatrix4d;
  node.has_matrix = false;
}

void edit_node(SceneNode& node, const NodeEdit& e, const std::string& where) {
  if (node.has_matrix && !e.rotation && !e.scale) {
    // Only the translation column changes: the rest of the matrix stays exactly as written.
    node.matrix[12] = (*e.translation)[0], node.matrix[13] = (*e.translation)[1], node.matrix[14] = (*e.translation)[2];
    return;
  }
  if (node.has_matrix) decompose_matrix(node, where);
  if (e.translation) node.translation = *e.translation;
  if (e.rotation) node.rotation = *e.rotation;
  if (e.scale) node.scale = *e.scale;
}

// `node "Box"`, `light 3`, `sky`: as parse_scene_edits labels an edit.
std::string label_of(const SceneEdit& edit) {
  if (const auto* e = std::get_if<NodeEdit>(&edit.change)) return refresh::target_label("node", e->node);
  if (const auto* e = std::get_if<LightEdit>(&edit.change)) return refresh::target_label("light", e->light);
  if (const auto* e = std::get_if<MaterialEdit>(&edit.change)) return refresh::target_label("material", e->material);
  return "sky";
}

std::vector<uint32_t> sorted(const std::set<uint32_t>& s) { return {s.begin(), s.end()}; }


// The edits applied in order to `next` (nodes' transforms only recorded in edit_of_node: moving
// what hangs under them is the caller's): the edited lights, materials and whether the sky changed.
struct EditedParts {
  std::set<uint32_t> lights, materials;
  bool sky = false;
  std::vector<std::string> edit_of_node;
  bool any_node() const {
    return std::any_of(edit_of_node.begin(), edit_of_node.end(), [](const std::string& s) { return !s.empty(); });
  }
};

EditedParts edit_parts(Scene& next, const std::vector<SceneEdit>& edits) {
  EditedParts parts;
  parts.edit_of_node.resize(next.nodes.size());
  for (size_t i = 0; i < edits.size(); ++i) {
    const SceneEdit& edit = edits[i];
    const std::string where = edit.where.empty() ? "edits[" + std::to_string(i) + "] (" + label_of(edit) + ")" : edit.where;
    refresh::check_edit_values(edit, where);
    if (const auto* e = std::get_if<NodeEdit>(&edit.change)) {
      const uint32_t node = refresh::resolve_node(next, e->node, where);
      edit_node(next.nodes[node], *e, where);
      parts.edit_of_node[node] = where;
    } else if (const auto* e = std::get_if<LightEdit>(&edit.change)) {
      const uint32_t light = refresh::resolve_light(next, e->light, where);
      edit_light(next.lights[light], *e, where);
      parts.lights.insert(light);
    } else if (const auto* e = std::get_if<MaterialEdit>(&edit.change)) {
      const uint32_t material = refresh::resolve_material(next, e->material, where);
      edit_material(next.materials[material], *e, where);
      parts.materials.insert(material);
    } else if (const auto* e = std::get_if<SkyEdit>(&edit.change)) {
      next.sky.constant = to_vec3(e->color);
      next.sky.environment = Texture{};
      parts.sky = true;
    }
  }
  return parts;
}

}  // namespace

InstanceTexels::InstanceTexels(const TexelGBuffer& gbuffer, size_t instance_count) {
  GroupedIndices by_instance = group_indices(gbuffer.texels.size(), instance_count,
                                             [&](size_t i) { return gbuffer.texels[i].instance; });
  start = std::move(by_instance.start);
  texels = std::move(by_instance.items);
}

InPlaceEdits apply_scene_edits_in_place(PersistedScene& persisted, const std::vector<SceneEdit>& edits,
                                        const InstanceTexels* by_instance, bool defer_texels) {
  Scene& scene = persisted.scene;
  // The parts edits change or read (names, the node tree, instances' world matrices, lights,
  // materials, the sky's colour), copied; the geometry, textures and an environment image are not.
  Scene next;
  next.nodes = scene.nodes;
  next.instances = scene.instances;
  next.lights = scene.lights;
  next.materials = scene.materials;
  next.sky.constant = scene.sky.constant;
  EditedParts parts = edit_parts(next, edits);
  refresh::PlannedMoves planned;
  std::vector<refresh::MovingTexel> texels;
  if (parts.any_node()) {
    planned = refresh::plan_moves(next, scene, parts.edit_of_node);
    parts.lights.insert(planned.lights.begin(), planned.lights.end());
    const bool indexed = by_instance && by_instance->start.size() == scene.instances.size() + 1;
    texels = refresh::moving_texels(planned, scene, persisted.gbuffer, persisted.atlas, indexed ? &by_instance->start : nullptr,
                                    indexed ? &by_instance->texels : nullptr);
  }
  InPlaceEdits out;
  EditEffects& effects = out.effects;
  effects.lights = sorted(parts.lights);
  effects.materials = sorted(parts.materials);
  effects.sky = parts.sky;
  effects.moved_instances = planned.instances;
  effects.moved_texels = texels.size();
  out.moved_deltas = planned.delta;
  for (size_t j = 0; j < planned.instances.size(); ++j) {
    out.moved_boxes_before.push_back(planned.triangles[j].box_before);
    out.moved_boxes_after.push_back(planned.triangles[j].box_after);
  }
  // Triangles in the order the instances' ranges ascend (ranges do not overlap: one instance per triangle).
  std::vector<size_t> by_first(planned.triangles.size());
  for (size_t j = 0; j < by_first.size(); ++j) by_first[j] = j;
  std::sort(by_first.begin(), by_first.end(), [&](size_t a, size_t b) { return planned.triangles[a].first < planned.triangles[b].first; });
  for (size_t j : by_first) {
    const refresh::MovedTriangles& m = planned.triangles[j];
    for (uint32_t t = m.first; t < m.first + m.count; ++t) out.moved_triangles.push_back(t);
    out.moved_triangles_before.insert(out.moved_triangles_before.end(), scene.positions.begin() + ptrdiff_t(m.first) * 3,
                                      scene.positions.begin() + (ptrdiff_t(m.first) + m.count) * 3);
  }

  // Commit: moves and copies of plain values only, nothing here throws.
  scene.nodes = std::move(next.nodes);
  scene.instances = std::move(next.instances);
  scene.lights = std::move(next.lights);
  scene.materials = std::move(next.materials);
  if (parts.sky) {
    scene.sky.constant = next.sky.constant;
    scene.sky.environment = Texture{};
  }
  for (const refresh::MovedTriangles& m : planned.triangles) m.write_into(scene);
  for (const refresh::MovingTexel& t : texels) out.moved_texels.push_back(uint32_t(t.index));
  if (texels.empty()) return out;
  refresh::PlannedMoves moves;  // what moved_texel reads of the plan: the moves' transforms
  moves.delta = std::move(planned.delta);
  out.move_texels = [&persisted, moves = std::move(moves), texels = std::move(texels)] {
    for_each_chunk(texels.size(), [&](size_t begin, size_t end) {  // each texel reads the scene and writes itself
      for (size_t k = begin; k < end; ++k) {
        LiveTexel& texel = persisted.gbuffer.texels[texels[k].index];
        texel = refresh::moved_texel(texel, texels[k], moves, persisted.scene, persisted.gbuffer, persisted.atlas);
      }
    }, 256);
  };
  if (!defer_texels) {
    out.move_texels();
    out.move_texels = nullptr;
  }
  return out;
}

EditEffects apply_scene_edits(PersistedScene& persisted, const std::vector<SceneEdit>& edits) {
  Scene next = persisted.scene;
  EditedParts parts = edit_parts(next, edits);
  std::set<uint32_t>& lights = parts.lights;
  const std::set<uint32_t>& materials = parts.materials;
  const bool sky = parts.sky;
  const std::vector<std::string>& edit_of_node = parts.edit_of_node;
  EditEffects effects;
  refresh::MovedGeometry moved;
  formats::SceneBvh bvh;
  if (parts.any_node()) {
    moved = refresh::move_under_edited_nodes(next, persisted.scene, persisted.gbuffer, persisted.atlas, edit_of_node);
    lights.insert(moved.lights.begin(), moved.lights.end());
    if (!moved.instances.empty() && !persisted.bvh.nodes.empty()) {
      Bvh4 refit = to_bvh4(persisted.bvh);
      try {
        refit_bvh4(refit, next.positions, &persisted.scene.positions);  // its boxes fit the scene before the edits
      } catch (const std::invalid_argument& e) {
        fail("scene", std::string("BVH: ") + e.what());
      }
      bvh = to_scene_bvh(refit);
    }
  }
  effects.lights = sorted(lights);
  effects.materials = sorted(materials);
  effects.sky = sky;
  effects.moved_instances = moved.instances;
  effects.moved_texels = moved.texels.size();

  // Commit: moves and assignments of plain values only, nothing here throws.
  persisted.scene = std::move(next);
  for (auto& [index, texel] : moved.texels) persisted.gbuffer.texels[index] = texel;
  if (!moved.instances.empty() && !persisted.bvh.nodes.empty()) persisted.bvh = std::move(bvh);
  return effects;
}

}  // namespace exitance
