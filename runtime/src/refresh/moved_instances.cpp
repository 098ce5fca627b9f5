#include "moved_instances.h"

#include <algorithm>
#include <atomic>
#include <mutex>
#include <cmath>
#include <cstring>
#include <optional>

#include "edit_checks.h"
#include "exitance/runtime/core/parallel_chunks.h"
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

// Moves one triangle of the slice by `delta`; false when the move collapses it.
bool move_triangle(MovedTriangles& m, uint32_t t, const Matrix4d& delta, bool mirrors) {
  Vec3* p = &m.positions[size_t(t) * 3];
  Vec3* n = &m.normals[size_t(t) * 3];
  for (int k = 0; k < 3; ++k) p[k] = transform_point(delta, p[k]);
  if (mirrors) {
    std::swap(p[1], p[2]);
    std::swap(n[1], n[2]);
    for (std::vector<Vec2>* uv : {&m.uv0, &m.lightmap_uv})
      if (!uv->empty()) std::swap((*uv)[size_t(t) * 3 + 1], (*uv)[size_t(t) * 3 + 2]);
    if (!m.vertex_color.empty()) {
      std::swap(m.vertex_color[size_t(t) * 3 + 1], m.vertex_color[size_t(t) * 3 + 2]);
      std::swap(m.vertex_alpha[size_t(t) * 3 + 1], m.vertex_alpha[size_t(t) * 3 + 2]);
    }
    if (!m.tangents.empty()) {
      std::swap(m.tangents[size_t(t) * 3 + 1], m.tangents[size_t(t) * 3 + 2]);
      std::swap(m.tangent_signs[size_t(t) * 3 + 1], m.tangent_signs[size_t(t) * 3 + 2]);
    }
  }
  const Vec3 face = cross(p[1] - p[0], p[2] - p[0]);
  const float face_length = length(face);
  if (!(face_length > 0.0f) || !std::isfinite(face_length) || !is_finite(p[0]) || !is_finite(p[1]) || !is_finite(p[2]))
    return false;
  for (int k = 0; k < 3; ++k) {
    // Cofactor = det * inverse-transpose: its sign undone so the normal keeps its side.
    const Vec3 v = transform_normal(delta, n[k]) * (mirrors ? -1.0f : 1.0f);
    const float v_length = length(v);
    const Vec3 moved_normal = v_length > 0.0f && std::isfinite(v_length) ? v / v_length : face / face_length;
    if (!m.tangents.empty()) {  // normal-map frames move with the surface
      const size_t c = size_t(t) * 3 + size_t(k);
      const TangentFrame frame = transform_tangent_frame(delta, {m.tangents[c], m.tangent_signs[c]}, n[k], moved_normal);
      m.tangents[c] = frame.tangent;
      m.tangent_signs[c] = frame.sign;
    }
    n[k] = moved_normal;
  }
  return true;
}

// Moves an instance's triangles (the slice) by `delta` (normals by its inverse transpose,
// renormalized), on all cores; the first collapsed triangle is named.
void move_triangles(MovedTriangles& m, const Instance& instance, const Matrix4d& delta, const std::string& where) {
  const bool mirrors = determinant3(delta) < 0;  // the importer flips the winding of mirrored instances: so do we
  std::atomic<uint32_t> first_collapsed{UINT32_MAX};
  std::mutex boxes;
  for_each_chunk(m.count, [&](size_t begin, size_t end) {
    WorldBox before, after;  // this chunk's (a union: the same bounds in any order)
    for (size_t t = begin; t < end; ++t) {
      for (size_t k = 0; k < 3; ++k) before.grow(m.positions[t * 3 + k]);
      if (!move_triangle(m, uint32_t(t), delta, mirrors))
        for (uint32_t v = first_collapsed.load(); t < v && !first_collapsed.compare_exchange_weak(v, uint32_t(t));) {}
      for (size_t k = 0; k < 3; ++k) after.grow(m.positions[t * 3 + k]);
    }
    const std::lock_guard<std::mutex> lock(boxes);
    m.box_before.grow(before), m.box_after.grow(after);
  }, 256);  // a block's few thousand triangles over all cores
  if (first_collapsed.load() != UINT32_MAX)
    fail(where, "the transform collapses triangle " + std::to_string(m.first + first_collapsed.load()) + " of instance \"" +
                    instance.name + "\" (zero area or not finite)");
}

template <typename T>
std::vector<T> corners_of(const std::vector<T>& all, size_t corner_count, uint32_t first, uint32_t count) {
  if (all.size() != corner_count) return {};
  return std::vector<T>(all.begin() + ptrdiff_t(first) * 3, all.begin() + (ptrdiff_t(first) + count) * 3);
}

template <typename T>
void put_corners(std::vector<T>& all, const std::vector<T>& slice, uint32_t first) {
  if (!slice.empty()) std::copy(slice.begin(), slice.end(), all.begin() + ptrdiff_t(first) * 3);
}

// Whether the unocclude step had pushed the texel off its surface point (on the scene it was
// derived on), and the texel's barycentrics there.
bool pushed_off_surface(const LiveTexel& texel, const Scene& scene, const InstanceRect& rect, const AtlasPage& page,
                        float& b1, float& b2) {
  texel_barycentrics(scene, rect, page.width, page.height, texel.triangle, texel.x, texel.y, b1, b2);
  return !same_bits(texel_surface_position(scene, texel.triangle, b1, b2), texel.position);
}

// A texel of a moved instance, re-derived on `next` as the rasterizer derives it (barycentrics
// `b1`, `b2` when given, as texel_barycentrics computes them on `next`); a texel the unocclude step
// had pushed off its surface point keeps that offset, moved rigidly by `delta`.
LiveTexel moved_texel(const LiveTexel& texel, bool pushed, const Scene& next, const InstanceRect& rect,
                      const AtlasPage& page, const Matrix4d& delta, const float* known_b1, const float* known_b2) {
  float b1, b2;
  if (known_b1 && known_b2)
    b1 = *known_b1, b2 = *known_b2;
  else
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

MovedTriangles MovedTriangles::of(const Scene& scene, uint32_t first, uint32_t count) {
  MovedTriangles m;
  const size_t corners = scene.positions.size();
  m.first = first, m.count = count;
  m.positions = corners_of(scene.positions, corners, first, count);
  m.normals = corners_of(scene.normals, corners, first, count);
  m.uv0 = corners_of(scene.uv0, corners, first, count);
  m.lightmap_uv = corners_of(scene.lightmap_uv, corners, first, count);
  m.vertex_color = corners_of(scene.vertex_color, corners, first, count);
  m.vertex_alpha = corners_of(scene.vertex_alpha, corners, first, count);
  m.tangents = corners_of(scene.tangents, corners, first, count);
  m.tangent_signs = corners_of(scene.tangent_signs, corners, first, count);
  return m;
}

void MovedTriangles::write_into(Scene& scene) const {
  put_corners(scene.positions, positions, first);
  put_corners(scene.normals, normals, first);
  put_corners(scene.uv0, uv0, first);
  put_corners(scene.lightmap_uv, lightmap_uv, first);
  put_corners(scene.vertex_color, vertex_color, first);
  put_corners(scene.vertex_alpha, vertex_alpha, first);
  put_corners(scene.tangents, tangents, first);
  put_corners(scene.tangent_signs, tangent_signs, first);
}

PlannedMoves plan_moves(Scene& next, const Scene& geometry, const std::vector<std::string>& edit_of_node) {
  const auto [responsible, world] = edited_world(next, edit_of_node);
  for (size_t i = 0; i < world.size(); ++i)
    if (!responsible[i].empty() && world[i] && (!finite_matrix(*world[i]) || !(std::fabs(determinant3(*world[i])) > 0)))
      fail(responsible[i], "the world transform of node " + std::to_string(i) + " is " +
                               (finite_matrix(*world[i]) ? "singular" : "not finite"));
  PlannedMoves planned;
  for (size_t k = 0; k < next.instances.size(); ++k) {
    Instance& instance = next.instances[k];
    const size_t node = size_t(instance.node);
    if (instance.node < 0 || node >= world.size() || responsible[node].empty() || !world[node]) continue;
    if (same_bits(*world[node], instance.world)) continue;  // a no-op edit moves nothing, bit for bit
    const std::optional<Matrix4d> inverse = affine_inverse(instance.world);
    if (!inverse) fail(responsible[node], "instance \"" + instance.name + "\" has a singular world transform");
    if (size_t(instance.first_triangle) + instance.triangle_count > geometry.triangle_count())
      fail("scene", "instance \"" + instance.name + "\" names triangles the scene does not have");
    const Matrix4d delta = multiply(*world[node], *inverse);
    MovedTriangles moved = MovedTriangles::of(geometry, instance.first_triangle, instance.triangle_count);
    move_triangles(moved, instance, delta, responsible[node]);
    instance.world = *world[node];
    planned.instances.push_back(uint32_t(k));
    planned.delta.push_back(delta);
    planned.triangles.push_back(std::move(moved));
  }
  for (size_t l = 0; l < next.lights.size(); ++l) {
    PunctualLight& light = next.lights[l];
    const size_t node = size_t(light.node);
    if (light.node < 0 || node >= world.size() || responsible[node].empty() || !world[node]) continue;
    const Vec3 position = light.position, direction = light.direction;
    if (!place_light(*world[node], light))
      fail(responsible[node], "the transform collapses the direction of light \"" + light.name + "\"");
    if (!same_bits(position, light.position) || !same_bits(direction, light.direction)) planned.lights.push_back(uint32_t(l));
  }
  return planned;
}

std::vector<MovingTexel> moving_texels(const PlannedMoves& planned, const Scene& before, const TexelGBuffer& gbuffer,
                                       const AtlasLayout& atlas, const std::vector<uint32_t>* texel_start,
                                       const std::vector<uint32_t>* texels_by_instance) {
  std::vector<MovingTexel> out;
  if (planned.instances.empty() || gbuffer.texels.empty()) return out;
  if (atlas.rects.size() != before.instances.size())
    fail("scene", "the atlas has " + std::to_string(atlas.rects.size()) + " rectangles for " +
                      std::to_string(before.instances.size()) + " instances; texels cannot be moved");
  std::vector<uint32_t> move_of(before.instances.size(), UINT32_MAX);
  for (size_t j = 0; j < planned.instances.size(); ++j) move_of[planned.instances[j]] = uint32_t(j);
  auto visit = [&](size_t i) {
    const LiveTexel& texel = gbuffer.texels[i];
    if (texel.instance >= move_of.size() || move_of[texel.instance] == UINT32_MAX) return;
    if (texel.page >= gbuffer.pages.size() || texel.triangle >= before.triangle_count())
      fail("scene", "texel " + std::to_string(i) + " names a page or triangle the scene does not have");
    out.push_back({i, move_of[texel.instance], false});
  };
  if (texel_start && texels_by_instance && texel_start->size() == before.instances.size() + 1) {
    for (uint32_t k : planned.instances)
      for (uint32_t e = (*texel_start)[k]; e < (*texel_start)[size_t(k) + 1]; ++e) visit((*texels_by_instance)[e]);
    auto by_index = [](const MovingTexel& a, const MovingTexel& b) { return a.index < b.index; };
    if (!std::is_sorted(out.begin(), out.end(), by_index)) std::sort(out.begin(), out.end(), by_index);  // one instance's ascend
  } else {
    for (size_t i = 0; i < gbuffer.texels.size(); ++i) visit(i);
  }
  for_each_chunk(out.size(), [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) {
      const LiveTexel& texel = gbuffer.texels[out[k].index];
      out[k].pushed = pushed_off_surface(texel, before, atlas.rects[texel.instance], gbuffer.pages[texel.page], out[k].b1, out[k].b2);
    }
  }, 256);  // a block's few thousand texels over all cores (0.4 ms in 10 chunks of 1 024 on a 16-core host)
  return out;
}

LiveTexel moved_texel(const LiveTexel& texel, const MovingTexel& moving, const PlannedMoves& planned, const Scene& next,
                      const TexelGBuffer& gbuffer, const AtlasLayout& atlas) {
  // A mirroring move reverses the triangle's corners (move_triangles): its barycentrics are derived again.
  const bool same_corners = !(determinant3(planned.delta[moving.move]) < 0);
  return moved_texel(texel, moving.pushed, next, atlas.rects[texel.instance], gbuffer.pages[texel.page], planned.delta[moving.move],
                     same_corners ? &moving.b1 : nullptr, same_corners ? &moving.b2 : nullptr);
}

MovedGeometry move_under_edited_nodes(Scene& next, const Scene& old, const TexelGBuffer& gbuffer,
                                      const AtlasLayout& atlas, const std::vector<std::string>& edit_of_node) {
  const PlannedMoves planned = plan_moves(next, next, edit_of_node);
  MovedGeometry moved;
  moved.instances = planned.instances;
  moved.lights = planned.lights;
  const std::vector<MovingTexel> texels = moving_texels(planned, old, gbuffer, atlas, nullptr, nullptr);
  for (const MovedTriangles& m : planned.triangles) m.write_into(next);
  for (const MovingTexel& t : texels)
    moved.texels.emplace_back(t.index, moved_texel(gbuffer.texels[t.index], t, planned, next, gbuffer, atlas));
  return moved;
}

}  // namespace exitance::refresh
