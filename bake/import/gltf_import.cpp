#include "exitance/bake/import/gltf_import.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "exitance/bake/import/gltf_accessor_reader.h"
#include "exitance/bake/import/gltf_file_load.h"
#include "exitance/bake/import/gltf_materials.h"
#include "exitance/bake/import/gltf_triangle_corners.h"
#include "exitance/bake/input_error.h"
#include "exitance/common/texture_sampling.h"
#include "exitance/runtime/node_transform.h"
#include "exitance/runtime/tangent_frames.h"

namespace exitance {
namespace {

constexpr size_t kMaxNodeDepth = 256;  // deeper hierarchies are hostile, not authored

using Mat4 = Matrix4d;  // column-major, as glTF stores it (node_transform.h: shared with the runtime's edits)

Mat4 identity() { return kIdentityMatrix4d; }

void require_finite(const std::vector<double>& values, size_t expected, const std::string& file,
                    const std::string& element, const char* what) {
  if (values.empty()) return;
  if (values.size() != expected)
    throw InputError(file, element, std::string(what) + " must have " + std::to_string(expected) + " numbers");
  for (double v : values)
    if (!std::isfinite(v)) throw InputError(file, element, std::string(what) + " is not finite");
}

Mat4 local_transform(const tinygltf::Node& node, const std::string& file, const std::string& element) {
  require_finite(node.matrix, 16, file, element, "matrix");
  require_finite(node.translation, 3, file, element, "translation");
  require_finite(node.rotation, 4, file, element, "rotation");
  require_finite(node.scale, 3, file, element, "scale");
  if (!node.matrix.empty()) {
    if (!node.translation.empty() || !node.rotation.empty() || !node.scale.empty())
      throw InputError(file, element, "has both a matrix and translation/rotation/scale");
    Mat4 m;
    for (size_t i = 0; i < 16; ++i) m[i] = node.matrix[i];
    return m;
  }
  std::array<double, 3> translation{0, 0, 0}, scale{1, 1, 1};
  std::array<double, 4> rotation{0, 0, 0, 1};
  if (!node.translation.empty()) std::copy_n(node.translation.begin(), 3, translation.begin());
  if (!node.rotation.empty()) {
    std::copy_n(node.rotation.begin(), 4, rotation.begin());
    const auto& q = rotation;
    if (std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]) < 1e-12)
      throw InputError(file, element, "rotation quaternion has zero length");
  }
  if (!node.scale.empty()) std::copy_n(node.scale.begin(), 3, scale.begin());
  return trs_matrix(translation, rotation, scale);
}

Vec3 to_vec3(const std::vector<float>& v, size_t i) { return {v[3 * i], v[3 * i + 1], v[3 * i + 2]}; }
Vec2 to_vec2(const std::vector<float>& v, size_t i) { return {v[2 * i], v[2 * i + 1]}; }

int attribute(const tinygltf::Primitive& primitive, const std::string& name) {
  auto it = primitive.attributes.find(name);
  return it == primitive.attributes.end() ? -1 : it->second;
}

// The node as written in the file, for Scene::nodes: its local transform exactly as given (the
// importer validates it when the default scene reaches the node; sanitize_unreached_node resets
// the others' unusable transforms, as such nodes are never drawn).
SceneNode scene_node(const tinygltf::Node& node) {
  SceneNode n;
  n.name = node.name;
  n.mesh = node.mesh >= 0 ? node.mesh : -1;
  if (node.matrix.size() == 16) {
    n.has_matrix = true;
    std::copy(node.matrix.begin(), node.matrix.end(), n.matrix.begin());
  }
  if (node.translation.size() == 3) std::copy(node.translation.begin(), node.translation.end(), n.translation.begin());
  if (node.rotation.size() == 4) std::copy(node.rotation.begin(), node.rotation.end(), n.rotation.begin());
  if (node.scale.size() == 3) std::copy(node.scale.begin(), node.scale.end(), n.scale.begin());
  return n;
}

void sanitize_unreached_node(SceneNode& n) {
  bool usable = true;
  for (double v : n.matrix) usable = usable && std::isfinite(v);
  for (double v : n.translation) usable = usable && std::isfinite(v);
  for (double v : n.rotation) usable = usable && std::isfinite(v);
  for (double v : n.scale) usable = usable && std::isfinite(v);
  const auto& q = n.rotation;
  usable = usable && q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] > 1e-24;
  if (n.has_matrix)
    usable = usable && n.translation == std::array<double, 3>{0, 0, 0} && q == std::array<double, 4>{0, 0, 0, 1} &&
             n.scale == std::array<double, 3>{1, 1, 1};
  if (usable) return;
  const SceneNode defaults;
  n.has_matrix = false;
  n.matrix = defaults.matrix;
  n.translation = defaults.translation;
  n.rotation = defaults.rotation;
  n.scale = defaults.scale;
}

// glTF's rules for a camera projection (finite as floats; a perspective zfar of 0 is infinite).
bool camera_projection_is_valid(const SceneCamera& c) {
  for (float v : {c.yfov, c.aspect_ratio, c.xmag, c.ymag, c.znear, c.zfar})
    if (!std::isfinite(v)) return false;
  if (c.type == SceneCamera::Type::Perspective)
    return c.yfov > 0 && c.aspect_ratio >= 0 && c.znear > 0 && (c.zfar == 0 || c.zfar > c.znear);
  return c.xmag != 0 && c.ymag != 0 && c.znear >= 0 && c.zfar > c.znear;
}

struct RepairCounts {
  size_t degenerate_triangles = 0;
  size_t recomputed_normals = 0;
  size_t non_finite_normals = 0;
  size_t renormalized_normals = 0;
  size_t zero_tangents = 0;
};

class SceneFlattener {
 public:
  SceneFlattener(const tinygltf::Model& model, const std::string& file, const ImportOptions& options, Scene& scene,
                 Diagnostics& diagnostics, uint32_t default_material,
                 std::vector<MeshWithoutLightmapUvs>* without_lightmap_uvs)
      : model_(model), file_(file), options_(options), scene_(scene), diagnostics_(diagnostics),
        default_material_(default_material), node_state_(model.nodes.size(), 0),
        without_lightmap_uvs_(without_lightmap_uvs), generated_mesh_(model.meshes.size(), -1) {
    scene_.nodes.reserve(model.nodes.size());
    for (const tinygltf::Node& node : model.nodes) scene_.nodes.push_back(scene_node(node));
  }

  void add_scene_roots(const std::vector<int>& roots) {
    struct Pending { int node; Mat4 parent; size_t depth; bool leaving; int parent_node; };
    std::vector<Pending> stack;
    for (auto it = roots.rbegin(); it != roots.rend(); ++it) stack.push_back({*it, identity(), 0, false, -1});
    while (!stack.empty()) {
      Pending item = stack.back();
      stack.pop_back();
      if (item.leaving) { node_state_[size_t(item.node)] = 2; continue; }
      const std::string element = "node " + std::to_string(item.node);
      if (item.node < 0 || size_t(item.node) >= model_.nodes.size())
        throw InputError(file_, element, "does not exist");
      if (node_state_[size_t(item.node)] == 1) throw InputError(file_, element, "is its own ancestor (cyclic node graph)");
      if (node_state_[size_t(item.node)] == 2)
        throw InputError(file_, element, "has more than one parent (glTF node graphs must be trees)");
      if (item.depth > kMaxNodeDepth)
        throw InputError(file_, element, "hierarchy is deeper than " + std::to_string(kMaxNodeDepth) + " levels");
      node_state_[size_t(item.node)] = 1;
      scene_.nodes[size_t(item.node)].in_scene = true;
      scene_.nodes[size_t(item.node)].parent = item.parent_node;
      const tinygltf::Node& node = model_.nodes[size_t(item.node)];
      const Mat4 world = multiply(item.parent, local_transform(node, file_, element));
      if (node.mesh >= 0) add_mesh_instance(item.node, node, world);
      else if (node.mesh < -1) throw InputError(file_, element, "mesh " + std::to_string(node.mesh) + " does not exist");
      add_light_if_any(item.node, node, world);
      add_camera_if_any(item.node, node);
      stack.push_back({item.node, world, item.depth, true, item.parent_node});
      for (auto child = node.children.rbegin(); child != node.children.rend(); ++child)
        stack.push_back({*child, world, item.depth + 1, false, item.node});
    }
    for (SceneNode& n : scene_.nodes)
      if (!n.in_scene) sanitize_unreached_node(n);
  }

  void report_repairs() const {
    if (repairs_.degenerate_triangles)
      diagnostics_.warn(file_ + ": " + std::to_string(repairs_.degenerate_triangles) + " degenerate triangles dropped");
    if (repairs_.recomputed_normals)
      diagnostics_.warn(file_ + ": " + std::to_string(repairs_.recomputed_normals) +
                        " zero or missing vertex normals replaced by face normals");
    if (repairs_.non_finite_normals)
      diagnostics_.warn(file_ + ": " + std::to_string(repairs_.non_finite_normals) +
                        " NaN or infinite vertex normals replaced by face normals");
    if (repairs_.renormalized_normals)
      diagnostics_.warn(file_ + ": " + std::to_string(repairs_.renormalized_normals) + " vertex normals renormalized");
    if (repairs_.zero_tangents)
      diagnostics_.warn(file_ + ": " + std::to_string(repairs_.zero_tangents) +
                        " zero TANGENT vectors: the normal map is not applied at those vertices");
  }

 private:
  void add_mesh_instance(int node_index, const tinygltf::Node& node, const Mat4& world) {
    const std::string node_element = "node " + std::to_string(node_index);
    if (size_t(node.mesh) >= model_.meshes.size())
      throw InputError(file_, node_element, "mesh " + std::to_string(node.mesh) + " does not exist");
    const tinygltf::Mesh& mesh = model_.meshes[size_t(node.mesh)];
    Instance instance;
    instance.node = node_index;
    instance.name = node.name.empty() ? mesh.name : node.name;
    instance.mesh = node.mesh;
    instance.first_triangle = uint32_t(scene_.triangle_count());
    instance.world = world;
    const uint32_t instance_index = uint32_t(scene_.instances.size());
    const bool flip_winding = determinant3(world) < 0;
    GeneratedUvTarget target = generated_uv_target(node.mesh, mesh, instance_index);
    for (size_t p = 0; p < mesh.primitives.size(); ++p)
      add_primitive(mesh.primitives[p], "mesh " + std::to_string(node.mesh) + " primitive " + std::to_string(p), world,
                    flip_winding, instance_index, target);
    instance.triangle_count = uint32_t(scene_.triangle_count()) - instance.first_triangle;
    if (instance.triangle_count > 0) scene_.instances.push_back(std::move(instance));
    else if (target.request) target.request->instances.pop_back();
  }

  // Where a mesh whose lightmap UVs will be generated records its local triangles (first instance
  // only) and each instance's corner mapping; request is null for a mesh with its own UVs.
  struct GeneratedUvTarget {
    MeshWithoutLightmapUvs* request = nullptr;
    bool first_instance = false;
    uint32_t local_triangles = 0;  // mesh triangles so far in this instance (all primitives)
  };

  GeneratedUvTarget generated_uv_target(int mesh_index, const tinygltf::Mesh& mesh, uint32_t instance_index) {
    const std::string uv_name = "TEXCOORD_" + std::to_string(options_.lightmap_uv_set);
    std::string missing;  // the element that lacks the set
    for (size_t p = 0; p < mesh.primitives.size() && missing.empty(); ++p) {
      const int mode = mesh.primitives[p].mode < 0 ? TINYGLTF_MODE_TRIANGLES : mesh.primitives[p].mode;
      if (mode > TINYGLTF_MODE_LINE_STRIP && mode <= TINYGLTF_MODE_TRIANGLE_FAN &&
          attribute(mesh.primitives[p], uv_name) < 0)
        missing = "mesh " + std::to_string(mesh_index) + " primitive " + std::to_string(p);
    }
    if (missing.empty() && !options_.generate_lightmap_uvs) return {};
    if (!without_lightmap_uvs_)
      throw InputError(file_, missing,
                       "has no " + uv_name + " lightmap UVs" +
                           (options_.lightmap_uv_set == 1 ? " (use --uv 0 to bake with TEXCOORD_0)" : ""));
    GeneratedUvTarget target;
    int& slot = generated_mesh_[size_t(mesh_index)];
    if (slot < 0) {
      slot = int(without_lightmap_uvs_->size());
      MeshWithoutLightmapUvs& request = without_lightmap_uvs_->emplace_back();
      request.mesh = mesh_index;
      request.name = mesh.name;
      request.missing_set = missing.empty() ? "" : uv_name;
      target.first_instance = true;
    }
    target.request = &(*without_lightmap_uvs_)[size_t(slot)];
    target.request->instances.push_back({instance_index, {}});
    return target;
  }

  void add_primitive(const tinygltf::Primitive& primitive, const std::string& element, const Mat4& world,
                     bool flip_winding, uint32_t instance_index, GeneratedUvTarget& generated) {
    const int mode = primitive.mode < 0 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
    if (mode <= TINYGLTF_MODE_LINE_STRIP) {
      diagnostics_.warn(file_ + ": " + element + ": points/lines primitive skipped (nothing to light)");
      return;
    }
    if (mode > TINYGLTF_MODE_TRIANGLE_FAN) throw InputError(file_, element, "mode " + std::to_string(mode) + " is invalid");
    const int position_accessor = attribute(primitive, "POSITION");
    if (position_accessor < 0) throw InputError(file_, element, "has no POSITION attribute");
    const std::vector<float> positions = read_accessor_floats(model_, position_accessor, 3, file_, "POSITION");
    const size_t vertex_count = positions.size() / 3;
    const std::string uv_name = "TEXCOORD_" + std::to_string(options_.lightmap_uv_set);
    auto read_optional = [&](const std::string& name, int components, NonFinite non_finite) {
      const int index = attribute(primitive, name);
      std::vector<float> values;
      if (index >= 0) {
        values = read_accessor_floats(model_, index, components, file_, name, non_finite);
        if (values.size() / size_t(components) != vertex_count)
          throw InputError(file_, "accessor " + std::to_string(index),
                           name + " count differs from POSITION count " + std::to_string(vertex_count));
      }
      return values;
    };
    // NaN/Inf normals are repaired per vertex (shading_normal); NaN/Inf UVs cannot be.
    const std::vector<float> normals = read_optional("NORMAL", 3, NonFinite::Keep);
    const std::vector<float> uv0 = read_optional("TEXCOORD_0", 2, NonFinite::Reject);
    // A mesh whose UVs are generated reads no set (a partial or broken one is ignored).
    const std::vector<float> lightmap_uv =
        generated.request ? std::vector<float>{} : read_optional(uv_name, 2, NonFinite::Reject);
    // COLOR_0: VEC3 or VEC4, float or normalized unsigned byte/short (glTF: linear, multiplies the
    // base colour and its alpha).
    std::vector<float> colors;
    int color_components = 0;
    if (const int color_accessor = attribute(primitive, "COLOR_0"); color_accessor >= 0) {
      const bool vec4 = size_t(color_accessor) < model_.accessors.size() &&
                        model_.accessors[size_t(color_accessor)].type == TINYGLTF_TYPE_VEC4;
      color_components = vec4 ? 4 : 3;
      colors = read_optional("COLOR_0", color_components, NonFinite::Reject);
      size_t clamped = 0;
      for (float& c : colors)
        if (c < 0.0f || c > 1.0f) c = std::clamp(c, 0.0f, 1.0f), ++clamped;
      if (clamped)  // as baseColorFactor above 1: an albedo above 1 would not conserve energy
        diagnostics_.warn(file_ + ": accessor " + std::to_string(color_accessor) + ": " + std::to_string(clamped) +
                          " COLOR_0 values outside [0, 1] clamped");
      if (!vertex_colors_) {  // corners before this primitive were white
        vertex_colors_ = true;
        scene_.vertex_color.assign(scene_.positions.size(), Vec3{1, 1, 1});
        scene_.vertex_alpha.assign(scene_.positions.size(), 1.0f);
      }
    }

    std::vector<uint32_t> indices;
    if (primitive.indices >= 0) {
      indices = read_accessor_indices(model_, primitive.indices, file_);
      for (uint32_t index : indices)
        if (index >= vertex_count)
          throw InputError(file_, "accessor " + std::to_string(primitive.indices),
                           "index " + std::to_string(index) + " is out of range (" + std::to_string(vertex_count) +
                               " vertices)");
    } else {
      indices.resize(vertex_count);
      for (size_t i = 0; i < vertex_count; ++i) indices[i] = uint32_t(i);
    }
    uint32_t material = default_material_;
    if (primitive.material >= 0) {
      if (size_t(primitive.material) >= model_.materials.size())
        throw InputError(file_, element, "material " + std::to_string(primitive.material) + " does not exist");
      material = uint32_t(primitive.material);
    }
    const std::vector<uint32_t> corners = triangle_corners(mode, indices);
    const TangentFrames frames = tangent_frames(primitive, scene_.materials[material], positions, normals, corners, read_optional);
    if (frames.normal_mapped && !tangents_) {  // corners before this primitive have no frame
      tangents_ = true;
      scene_.tangents.assign(scene_.positions.size(), Vec3(0));
      scene_.tangent_signs.assign(scene_.positions.size(), 1.0f);
    }
    const uint32_t first_local_triangle = generated.local_triangles;
    generated.local_triangles += uint32_t(corners.size() / 3);
    if (generated.request && generated.first_instance) {
      const uint32_t base = uint32_t(generated.request->positions.size());
      for (size_t i = 0; i < vertex_count; ++i) generated.request->positions.push_back(to_vec3(positions, i));
      for (size_t t = 0; t + 2 < corners.size(); t += 3)
        for (size_t k = 0; k < 3; ++k) generated.request->indices.push_back(base + corners[t + k]);
    }
    for (size_t t = 0; t + 2 < corners.size(); t += 3) {
      std::array<uint32_t, 3> v{corners[t], corners[t + 1], corners[t + 2]};
      std::array<uint32_t, 3> local_corner{0, 1, 2};
      if (flip_winding) std::swap(v[1], v[2]), std::swap(local_corner[1], local_corner[2]);
      std::array<Vec3, 3> p;
      for (int k = 0; k < 3; ++k) p[size_t(k)] = transform_point(world, to_vec3(positions, v[size_t(k)]));
      const Vec3 face = cross(p[1] - p[0], p[2] - p[0]);
      const float face_length = length(face);
      if (!(face_length > 0.0f) || !std::isfinite(face_length)) {
        ++repairs_.degenerate_triangles;
        continue;
      }
      const Vec3 face_normal = face / face_length;
      for (int k = 0; k < 3; ++k) {
        const uint32_t vi = v[size_t(k)];
        scene_.positions.push_back(p[size_t(k)]);
        scene_.normals.push_back(shading_normal(normals, vi, world, face_normal, flip_winding));
        if (tangents_) {
          const TangentFrame frame =
              frames.normal_mapped
                  ? transform_tangent_frame(world, frames.local[vi], frames.local_normals[vi], scene_.normals.back())
                  : TangentFrame{};
          scene_.tangents.push_back(frame.tangent);
          scene_.tangent_signs.push_back(frame.sign);
        }
        scene_.uv0.push_back(uv0.empty() ? Vec2{} : to_vec2(uv0, vi));
        scene_.lightmap_uv.push_back(generated.request ? Vec2{} : to_vec2(lightmap_uv, vi));
        if (generated.request)
          generated.request->instances.back().corners.push_back(3 * (first_local_triangle + uint32_t(t / 3)) +
                                                                local_corner[size_t(k)]);
        if (vertex_colors_) {
          const size_t c = size_t(vi) * size_t(color_components);
          scene_.vertex_color.push_back(colors.empty() ? Vec3{1, 1, 1} : Vec3{colors[c], colors[c + 1], colors[c + 2]});
          scene_.vertex_alpha.push_back(color_components == 4 ? colors[c + 3] : 1.0f);
        }
      }
      scene_.triangle_material.push_back(material);
      scene_.triangle_instance.push_back(instance_index);
    }
  }

  // A primitive's tangent frames in its local space (tangent_frames.h), for materials with a normal
  // map: the TANGENT attribute when present, else generated from the UVs the normal map reads
  // (after its KHR_texture_transform, so the tangent follows the texture's own u axis).
  struct TangentFrames {
    bool normal_mapped = false;
    std::vector<TangentFrame> local;  // per vertex
    std::vector<Vec3> local_normals;  // per vertex, the normals the frames were built against
  };
  template <class ReadOptional>
  TangentFrames tangent_frames(const tinygltf::Primitive& primitive, const Material& material,
                               const std::vector<float>& positions, const std::vector<float>& normals,
                               const std::vector<uint32_t>& corners, ReadOptional& read_optional) {
    TangentFrames out;
    if (material.normal_texture.texture < 0) return out;
    out.normal_mapped = true;
    const size_t vertex_count = positions.size() / 3;
    std::vector<Vec3> local_positions(vertex_count), given_normals;
    for (size_t i = 0; i < vertex_count; ++i) local_positions[i] = to_vec3(positions, i);
    if (!normals.empty())
      for (size_t i = 0; i < vertex_count; ++i) given_normals.push_back(to_vec3(normals, i));
    out.local_normals = tangent_space_normals(local_positions, given_normals, corners);
    if (const std::vector<float> tangents = read_optional("TANGENT", 4, NonFinite::Reject); !tangents.empty()) {
      out.local.resize(vertex_count);
      for (size_t i = 0; i < vertex_count; ++i) {
        const Vec3 t{tangents[4 * i], tangents[4 * i + 1], tangents[4 * i + 2]};
        const float t_length = length(t);
        if (!(t_length > 1e-6f)) {
          ++repairs_.zero_tangents;
          continue;
        }
        out.local[i] = {t / t_length, tangents[4 * i + 3] < 0.0f ? -1.0f : 1.0f};
      }
      return out;
    }
    const TextureTransform& transform = material.normal_texture.transform;
    const std::vector<float> uv_values = read_optional("TEXCOORD_" + std::to_string(transform.tex_coord), 2, NonFinite::Reject);
    std::vector<Vec2> uvs(vertex_count, Vec2{0, 0});
    if (!uv_values.empty())
      for (size_t i = 0; i < vertex_count; ++i)
        uvs[i] = transform_texture_coordinate(to_vec2(uv_values, i), transform.offset, transform.scale, transform.rotation);
    out.local = generate_vertex_tangents(local_positions, out.local_normals, uvs, corners);
    return out;
  }

  Vec3 shading_normal(const std::vector<float>& normals, uint32_t vi, const Mat4& world, Vec3 face_normal,
                      bool flip_winding) {
    if (normals.empty()) {
      ++repairs_.recomputed_normals;
      return face_normal;
    }
    const Vec3 local = to_vec3(normals, vi);
    if (!is_finite(local)) {
      ++repairs_.non_finite_normals;
      return face_normal;
    }
    const float local_length = length(local);
    if (!(local_length > 1e-6f)) {
      ++repairs_.recomputed_normals;
      return face_normal;
    }
    if (std::fabs(local_length - 1.0f) > 1e-3f) ++repairs_.renormalized_normals;
    const Vec3 n = transform_normal(world, local);
    const float n_length = length(n);
    if (!(n_length > 0.0f) || !std::isfinite(n_length)) {
      ++repairs_.recomputed_normals;
      return face_normal;
    }
    // The cofactor matrix is det * inverse-transpose: a mirroring transform (det < 0) flips it.
    return flip_winding ? -(n / n_length) : n / n_length;
  }

  void add_light_if_any(int node_index, const tinygltf::Node& node, const Mat4& world) {
    auto ext = node.extensions.find("KHR_lights_punctual");
    if (ext == node.extensions.end()) return;
    const std::string element = "node " + std::to_string(node_index) + " KHR_lights_punctual";
    if (!ext->second.IsObject() || !ext->second.Has("light") || !ext->second.Get("light").IsInt())
      throw InputError(file_, element, "has no integer 'light'");
    const int light_index = ext->second.Get("light").GetNumberAsInt();
    if (light_index < 0 || size_t(light_index) >= model_.lights.size())
      throw InputError(file_, element, "light " + std::to_string(light_index) + " does not exist");
    const tinygltf::Light& source = model_.lights[size_t(light_index)];
    const std::string light_element = "light " + std::to_string(light_index);
    PunctualLight light;
    light.name = source.name;
    Vec3 color{1, 1, 1};
    if (!source.color.empty()) {
      if (source.color.size() != 3) throw InputError(file_, light_element, "color must have 3 numbers");
      color = {float(source.color[0]), float(source.color[1]), float(source.color[2])};
    }
    light.intensity = color * float(source.intensity);
    if (!is_finite(light.intensity) || light.intensity.x < 0 || light.intensity.y < 0 || light.intensity.z < 0)
      throw InputError(file_, light_element, "color * intensity must be finite and >= 0");
    if (!place_light(world, light)) throw InputError(file_, element, "node transform collapses the light direction");
    if (source.type == "point") {
      light.type = PunctualLight::Type::Point;
    } else if (source.type == "spot") {
      light.type = PunctualLight::Type::Spot;
      const double inner = source.spot.innerConeAngle, outer = source.spot.outerConeAngle;
      if (!(inner >= 0 && inner < outer && outer <= M_PI / 2 + 1e-9))
        throw InputError(file_, light_element, "spot cone angles need 0 <= inner < outer <= pi/2");
      light.cos_inner = float(std::cos(inner));
      light.cos_outer = float(std::cos(outer));
    } else if (source.type == "directional") {
      light.type = PunctualLight::Type::Directional;
    } else {
      throw InputError(file_, light_element, "type '" + source.type + "' is not point, spot or directional");
    }
    if (source.range > 0 && light.type != PunctualLight::Type::Directional)
      diagnostics_.warn(file_ + ": " + light_element +
                        ": range ignored (baked lighting uses the physical inverse-square falloff)");
    light.node = node_index;
    scene_.nodes[size_t(node_index)].light = int(scene_.lights.size());
    scene_.lights.push_back(std::move(light));
  }

  // A camera with an invalid projection is dropped with a warning: it does not affect the bake.
  void add_camera_if_any(int node_index, const tinygltf::Node& node) {
    if (node.camera < 0) return;
    const std::string element = "node " + std::to_string(node_index);
    if (size_t(node.camera) >= model_.cameras.size())
      throw InputError(file_, element, "camera " + std::to_string(node.camera) + " does not exist");
    const tinygltf::Camera& source = model_.cameras[size_t(node.camera)];
    const std::string camera_element = "camera " + std::to_string(node.camera);
    SceneCamera camera;
    camera.name = source.name;
    camera.node = node_index;
    if (source.type == "perspective") {
      camera.type = SceneCamera::Type::Perspective;
      camera.yfov = float(source.perspective.yfov);
      camera.aspect_ratio = float(source.perspective.aspectRatio);
      camera.znear = float(source.perspective.znear);
      camera.zfar = float(source.perspective.zfar);
    } else if (source.type == "orthographic") {
      camera.type = SceneCamera::Type::Orthographic;
      camera.xmag = float(source.orthographic.xmag);
      camera.ymag = float(source.orthographic.ymag);
      camera.znear = float(source.orthographic.znear);
      camera.zfar = float(source.orthographic.zfar);
    } else {
      diagnostics_.warn(file_ + ": " + camera_element + ": type '" + source.type +
                        "' is not perspective or orthographic; camera ignored");
      return;
    }
    if (!camera_projection_is_valid(camera)) {
      diagnostics_.warn(file_ + ": " + camera_element +
                        ": invalid projection (glTF needs yfov > 0, znear > 0, zfar > znear; "
                        "orthographic xmag, ymag non-zero); camera ignored");
      return;
    }
    scene_.nodes[size_t(node_index)].camera = int(scene_.cameras.size());
    scene_.cameras.push_back(std::move(camera));
  }

  const tinygltf::Model& model_;
  const std::string& file_;
  const ImportOptions& options_;
  Scene& scene_;
  bool vertex_colors_ = false;  // some primitive so far has COLOR_0: every corner gets a colour
  bool tangents_ = false;  // some primitive so far has a normal-mapped material: every corner gets a frame
  Diagnostics& diagnostics_;
  uint32_t default_material_;
  std::vector<uint8_t> node_state_;  // 0 unvisited, 1 on the current path, 2 done
  RepairCounts repairs_;
  std::vector<MeshWithoutLightmapUvs>* without_lightmap_uvs_;
  std::vector<int> generated_mesh_;  // per glTF mesh: its index in *without_lightmap_uvs_, or -1
};

}  // namespace

Scene import_gltf(const std::string& path, const ImportOptions& options, Diagnostics& diagnostics,
                  std::vector<MeshWithoutLightmapUvs>* without_lightmap_uvs) {
  if (without_lightmap_uvs) without_lightmap_uvs->clear();
  const tinygltf::Model model = load_gltf_model(path, diagnostics);
  Scene scene;
  const uint32_t default_material = import_gltf_materials(model, path, scene, diagnostics);
  std::vector<int> roots;
  if (model.defaultScene >= 0 || !model.scenes.empty()) {
    const int scene_index = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (size_t(scene_index) >= model.scenes.size())
      throw InputError(path, "scene " + std::to_string(scene_index), "does not exist");
    roots = model.scenes[size_t(scene_index)].nodes;
  } else {
    throw InputError(path, "scenes", "the file defines no scene to bake");
  }
  SceneFlattener flattener(model, path, options, scene, diagnostics, default_material, without_lightmap_uvs);
  flattener.add_scene_roots(roots);
  flattener.report_repairs();
  if (scene.triangle_count() == 0) throw InputError(path, "scene", "contains no triangles to bake");
  return scene;
}

}  // namespace exitance
