#include "moved_instances.h"

#include <cmath>
#include <cstring>

#include "edit_checks.h"
#include "exitance/runtime/node_transform.h"
#include "exitance/runtime/tangent_frames.h"
#include "exitance/runtime/texel_surface.h"

namespace exitance::refresh {
namespace {

bool same_bits(const Matrix4d& a, const Matrix4d& b) { return std::memcmp(a.data(), b.data(), sizeof(Matrix4d)) == 0; }
bool same_bits(Vec3 a, Vec3 b) { return std::memcmp(&a, &b, sizeof(Vec3)) == 0; }

bool finite_matrix(const Matrix4d& m) {
  for (double v : m)
    if (!std::isfinite(v)) return false;
  return true;
}

// The label of the edit that moves node i: its own or its nearest edited ancestor's ("" if none).
std::vector<std::string> responsible_edits(const Scene& scene, const std::vector<std::string>& edit_of_node) {
  std::vector<std::string> out(scene.nodes.size());
  for (size_t i = 0; i < scene.nodes.size(); ++i) {
    size_t steps = 0;
    for (int at = int(i); at >= 0 && size_t(at) < scene.nodes.size() && steps <= scene.nodes.size();
         at = scene.nodes[size_t(at)].parent, ++steps)
      if (!edit_of_node[size_t(at)].empty()) {
        out[i] = edit_of_node[size_t(at)];
        break;
      }
  }
  return out;
}

// Moves instance k's triangles by `delta` (normals by its inverse transpose, renormalized).
void move_triangles(Scene& next, const Instance& instance, const Matrix4d& delta, const std::string& where) {
  const double det = determinant3(delta);
  const bool mirrors = det < 0;  // the importer flips the winding of mirrored instances: so do we
  for (uint32_t t = instance.first_triangle; t < instance.first_triangle + instance.triangle_count; ++t) {
    Vec3* p = &next.positions[size_t(t) * 3];
    Vec3* n = &next.normals[size_t(t) * 3];
    for (int k = 0; k < 3; ++k) p[k] = transform_point(delta, p[k]);
    if (mirrors) {
      std::swap(p[1], p[2]);
      std::swap(n[1], n[2]);
      for (std::vector<Vec2>* uv : {&next.uv0, &next.lightmap_uv})
        if (uv->size() == next.positions.size()) std::swap((*uv)[size_t(t) * 3 + 1], (*uv)[size_t(t) * 3 + 2]);
      if (next.vertex_color.size() == next.positions.size()) {
        std::swap(next.vertex_color[size_t(t) * 3 + 1], next.vertex_color[size_t(t) * 3 + 2]);
        std::swap(next.vertex_alpha[size_t(t) * 3 + 1], next.vertex_alpha[size_t(t) * 3 + 2]);
      }
      if (next.tangents.size() == next.positions.size()) {
        std::swap(next.tangents[size_t(t) * 3 + 1], next.tangents[size_t(t) * 3 + 2]);
        std::swap(next.tangent_signs[size_t(t) * 3 + 1], next.tangent_signs[size_t(t) * 3 + 2]);
      }
    }
    const Vec3 face = cross(p[1] - p[0], p[2] - p[0]);
    const float face_length = length(face);
    if (!(face_length > 0.0f) || !std::isfinite(face_length) || !is_finite(p[0]) || !is_finite(p[1]) || !is_finite(p[2]))
      fail(where, "the transform collapses triangle " + std::to_string(t) + " of instance \"" + instance.name +
                      "\" (zero area or not finite)");
    for (int k = 0; k < 3; ++k) {
      // Cofactor = det * inverse-transpose: its sign undone so the normal keeps its side.
      const Vec3 m = transform_normal(delta, n[k]) * (mirrors ? -1.0f : 1.0f);
      const float m_length = length(m);
      const Vec3 moved_normal = m_length > 0.0f && std::isfinite(m_length) ? m / m_length : face / face_length;
      if (next.tangents.size() == next.positions.size()) {  // normal-map frames move with the surface
        const size_t c = size_t(t) * 3 + size_t(k);
        const TangentFrame frame =
            transform_tangent_frame(delta, {next.tangents[c], next.tangent_signs[c]}, n[k], moved_normal);
        next.tangents[c] = frame.tangent;
        next.tangent_signs[c] = frame.sign;
      }
      n[k] = moved_normal;
    }
  }
}

// Texel i of a moved instance, re-derived on `next` as the rasterizer derives it; a texel the
// unocclude step had pushed off its surface point keeps that offset, moved rigidly by `delta`.
LiveTexel moved_texel(const LiveTexel& texel, const Scene& next, const Scene& old, const InstanceRect& rect,
                      const AtlasPage& page, const Matrix4d& delta) {
  float b1, b2;
  texel_barycentrics(old, rect, page.width, page.height, texel.triangle, texel.x, texel.y, b1, b2);
  const bool pushed = !same_bits(texel_surface(old, texel.triangle, b1, b2).position, texel.position);
  texel_barycentrics(next, rect, page.width, page.height, texel.triangle, texel.x, texel.y, b1, b2);
  const TexelSurface surface = texel_surface(next, texel.triangle, b1, b2);
  LiveTexel moved = texel;
  moved.position = pushed ? transform_point(delta, texel.position) : surface.position;
  moved.geometric_normal = surface.geometric_normal;
  moved.shading_normal = surface.shading_normal;
  moved.albedo = surface.albedo;
  moved.world_texel_size = triangle_world_texel_size(next, texel.triangle, rect, page.width, page.height);
  return moved;
}

// Per node of `next`: the edit responsible for moving it ("" if none) and its world matrix.
struct EditedWorld {
  std::vector<std::string> responsible;
  std::vector<std::optional<Matrix4d>> world;
};

EditedWorld edited_world(const Scene& next, const std::vector<std::string>& edit_of_node) {
  EditedWorld w;
  w.responsible = responsible_edits(next, edit_of_node);
  try {
    w.world = node_world_matrices(next);
  } catch (const std::invalid_argument& e) {
    fail("scene", std::string("node hierarchy: ") + e.what());
  }
  return w;
}

}  // namespace

bool moves_an_instance(const Scene& next, const std::vector<std::string>& edit_of_node) {
  const auto [responsible, world] = edited_world(next, edit_of_node);
  for (const Instance& instance : next.instances) {
    const size_t node = size_t(instance.node);
    if (instance.node < 0 || node >= world.size() || responsible[node].empty() || !world[node]) continue;
    if (!same_bits(*world[node], instance.world)) return true;
  }
  return false;
}

MovedGeometry move_under_edited_nodes(Scene& next, const Scene& old, const TexelGBuffer& gbuffer,
                                      const AtlasLayout& atlas, const std::vector<std::string>& edit_of_node) {
  const auto [responsible, world] = edited_world(next, edit_of_node);
  for (size_t i = 0; i < world.size(); ++i)
    if (!responsible[i].empty() && world[i] && (!finite_matrix(*world[i]) || !(std::fabs(determinant3(*world[i])) > 0)))
      fail(responsible[i], "the world transform of node " + std::to_string(i) + " is " +
                               (finite_matrix(*world[i]) ? "singular" : "not finite"));

  MovedGeometry moved;
  std::vector<Matrix4d> delta(next.instances.size());
  for (size_t k = 0; k < next.instances.size(); ++k) {
    Instance& instance = next.instances[k];
    const size_t node = size_t(instance.node);
    if (instance.node < 0 || node >= world.size() || responsible[node].empty() || !world[node]) continue;
    if (same_bits(*world[node], instance.world)) continue;  // a no-op edit moves nothing, bit for bit
    const std::optional<Matrix4d> inverse = affine_inverse(instance.world);
    if (!inverse) fail(responsible[node], "instance \"" + instance.name + "\" has a singular world transform");
    delta[k] = multiply(*world[node], *inverse);
    move_triangles(next, instance, delta[k], responsible[node]);
    instance.world = *world[node];
    moved.instances.push_back(uint32_t(k));
  }
  for (size_t l = 0; l < next.lights.size(); ++l) {
    PunctualLight& light = next.lights[l];
    const size_t node = size_t(light.node);
    if (light.node < 0 || node >= world.size() || responsible[node].empty() || !world[node]) continue;
    const Vec3 position = light.position, direction = light.direction;
    if (!place_light(*world[node], light))
      fail(responsible[node], "the transform collapses the direction of light \"" + light.name + "\"");
    if (!same_bits(position, light.position) || !same_bits(direction, light.direction)) moved.lights.push_back(uint32_t(l));
  }
  if (moved.instances.empty() || gbuffer.texels.empty()) return moved;
  if (atlas.rects.size() != next.instances.size())
    fail("scene", "the atlas has " + std::to_string(atlas.rects.size()) + " rectangles for " +
                      std::to_string(next.instances.size()) + " instances; texels cannot be moved");
  std::vector<uint8_t> is_moved(next.instances.size(), 0);
  for (uint32_t k : moved.instances) is_moved[k] = 1;
  for (size_t i = 0; i < gbuffer.texels.size(); ++i) {
    const LiveTexel& texel = gbuffer.texels[i];
    if (texel.instance >= is_moved.size() || !is_moved[texel.instance]) continue;
    if (texel.page >= gbuffer.pages.size() || texel.triangle >= next.triangle_count())
      fail("scene", "texel " + std::to_string(i) + " names a page or triangle the scene does not have");
    moved.texels.emplace_back(i, moved_texel(texel, next, old, atlas.rects[texel.instance], gbuffer.pages[texel.page],
                                             delta[texel.instance]));
  }
  return moved;
}

}  // namespace exitance::refresh
