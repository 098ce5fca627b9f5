#include "gltf_geometry.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <optional>
#include <utility>

#include "engine_options.h"

namespace engine_sample {
namespace {

using Matrix = std::array<double, 16>;  // column-major, as glTF's `matrix`

constexpr Matrix kIdentity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

Matrix multiply(const Matrix& a, const Matrix& b) {
  Matrix m{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      for (int k = 0; k < 4; ++k) m[size_t(c * 4 + r)] += a[size_t(k * 4 + r)] * b[size_t(c * 4 + k)];
  return m;
}

// glTF: a node's local transform is its matrix, or T * R * S (the quaternion normalized, as bake's importer does).
Matrix local_transform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    Matrix m;
    std::copy(node.matrix.begin(), node.matrix.end(), m.begin());
    return m;
  }
  std::array<double, 3> t{0, 0, 0}, s{1, 1, 1};
  std::array<double, 4> q{0, 0, 0, 1};
  if (node.translation.size() == 3) std::copy(node.translation.begin(), node.translation.end(), t.begin());
  if (node.rotation.size() == 4) std::copy(node.rotation.begin(), node.rotation.end(), q.begin());
  if (node.scale.size() == 3) std::copy(node.scale.begin(), node.scale.end(), s.begin());
  const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const double x = q[0] / len, y = q[1] / len, z = q[2] / len, w = q[3] / len;
  // Column-major R * S, then the translation.
  return {(1 - 2 * (y * y + z * z)) * s[0], 2 * (x * y + z * w) * s[0], 2 * (x * z - y * w) * s[0], 0,
          2 * (x * y - z * w) * s[1], (1 - 2 * (x * x + z * z)) * s[1], 2 * (y * z + x * w) * s[1], 0,
          2 * (x * z + y * w) * s[2], 2 * (y * z - x * w) * s[2], (1 - 2 * (x * x + y * y)) * s[2], 0,
          t[0], t[1], t[2], 1};
}

double determinant3(const Matrix& m) {
  return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) + m[8] * (m[1] * m[6] - m[5] * m[2]);
}

// An accessor's elements in its buffer, bounds-checked once.
class AccessorView {
 public:
  AccessorView(const tinygltf::Model& model, int index, const std::string& element) : element_(element) {
    if (index < 0 || size_t(index) >= model.accessors.size())
      throw UsageError(element + ": accessor " + std::to_string(index) + " does not exist");
    const tinygltf::Accessor& a = model.accessors[size_t(index)];
    if (a.sparse.isSparse) throw UsageError(element + ": sparse accessors are not read by this sample");
    count_ = a.count;
    component_type_ = a.componentType;
    type_ = a.type;
    normalized_ = a.normalized;
    const int component_bytes = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
    const int components = tinygltf::GetNumComponentsInType(uint32_t(a.type));
    if (component_bytes <= 0 || components <= 0)
      throw UsageError(element + ": accessor " + std::to_string(index) + " has an unknown type");
    element_bytes_ = size_t(component_bytes) * size_t(components);
    if (a.bufferView < 0) return;  // all zeros (glTF allows an accessor without a buffer view)
    if (size_t(a.bufferView) >= model.bufferViews.size()) throw UsageError(element + ": buffer view does not exist");
    const tinygltf::BufferView& view = model.bufferViews[size_t(a.bufferView)];
    if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size())
      throw UsageError(element + ": buffer does not exist");
    const std::vector<unsigned char>& buffer = model.buffers[size_t(view.buffer)].data;
    stride_ = view.byteStride ? view.byteStride : element_bytes_;
    const size_t span = count_ ? a.byteOffset + stride_ * (count_ - 1) + element_bytes_ : 0;
    if (view.byteOffset + view.byteLength > buffer.size() || span > view.byteLength)
      throw UsageError(element + ": accessor " + std::to_string(index) + " reads past its buffer");
    data_ = buffer.data() + view.byteOffset + a.byteOffset;
  }

  size_t count() const { return count_; }
  int component_type() const { return component_type_; }
  int type() const { return type_; }
  bool normalized() const { return normalized_; }

  // Component c of element i as a float: floats as stored, normalized integers divided by their maximum.
  float component(size_t i, size_t c) const {
    if (!data_) return 0.0f;
    const unsigned char* p = data_ + i * stride_;
    switch (component_type_) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float v;
        std::memcpy(&v, p + 4 * c, 4);
        return v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return float(p[c]) / 255.0f;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p + 2 * c, 2);
        return float(v) / 65535.0f;
      }
      default: throw UsageError(element_ + ": component type " + std::to_string(component_type_) + " is not read");
    }
  }

  uint32_t index(size_t i) const {
    if (!data_) return 0;
    const unsigned char* p = data_ + i * stride_;
    switch (component_type_) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return p[0];
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return v;
      }
      default: throw UsageError(element_ + ": indices of component type " + std::to_string(component_type_));
    }
  }

 private:
  std::string element_;
  size_t count_ = 0, element_bytes_ = 0, stride_ = 0;
  int component_type_ = 0, type_ = 0;
  bool normalized_ = false;
  const unsigned char* data_ = nullptr;
};

int attribute(const tinygltf::Primitive& primitive, const char* name) {
  const auto it = primitive.attributes.find(name);
  return it == primitive.attributes.end() ? -1 : it->second;
}

// As bake's importer numbers a primitive's triangles (bake/import/gltf_triangle_corners.h).
std::vector<uint32_t> triangle_list(int mode, const std::vector<uint32_t>& indices) {
  std::vector<uint32_t> out;
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    out.assign(indices.begin(), indices.begin() + long(indices.size() / 3 * 3));
  } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    for (size_t i = 2; i < indices.size(); ++i)
      if (i % 2 == 0)
        out.insert(out.end(), {indices[i - 2], indices[i - 1], indices[i]});
      else
        out.insert(out.end(), {indices[i - 1], indices[i - 2], indices[i]});
  } else {  // fan
    for (size_t i = 2; i < indices.size(); ++i) out.insert(out.end(), {indices[0], indices[i - 1], indices[i]});
  }
  return out;
}

// What bake lights with (bake/import/gltf_materials.cpp, common/material.h diffuse_albedo_of); a
// primitive without a material is white diffuse, as bake treats it.
void set_material(const tinygltf::Model& model, int index, Draw& draw) {
  if (index < 0 || size_t(index) >= model.materials.size()) {
    draw.albedo = {1, 1, 1};
    return;
  }
  const tinygltf::Material& m = model.materials[size_t(index)];
  const std::vector<double>& base = m.pbrMetallicRoughness.baseColorFactor;
  const double metallic = m.pbrMetallicRoughness.metallicFactor;
  for (size_t c = 0; c < 3; ++c) {
    const double b = base.size() >= 3 ? std::min(base[c], 1.0) : 1.0;
    draw.albedo[c] = float(std::clamp(b * (1.0 - metallic), 0.0, 1.0));
  }
  double strength = 1.0;
  const auto ext = m.extensions.find("KHR_materials_emissive_strength");
  if (ext != m.extensions.end() && ext->second.Has("emissiveStrength"))
    strength = ext->second.Get("emissiveStrength").GetNumberAsDouble();
  for (size_t c = 0; c < 3; ++c)
    draw.emission[c] = float((m.emissiveFactor.size() == 3 ? m.emissiveFactor[c] : 0.0) * strength);
  draw.double_sided = m.doubleSided;
}

class SceneLoader {
 public:
  SceneLoader(const tinygltf::Model& model, const std::string& file, const ExitanceBundle* bundle)
      : model_(model), file_(file) {
    for (uint32_t i = 0; i < exitance_bundle_instance_count(bundle); ++i) {
      ExitanceInstanceInfo info;
      if (exitance_bundle_instance(bundle, i, &info) != EXITANCE_ERROR_NONE)
        throw std::runtime_error(std::string("exitance_bundle_instance: ") + exitance_last_error_message());
      instances_[{int(info.node), int(info.mesh)}] = info;
    }
  }

  // Depth-first from the default scene's roots, world = parent x local (glTF).
  void add_scene(SceneGeometry& out) {
    if (model_.scenes.empty()) throw UsageError(file_ + ": the file defines no scene");
    const int scene = model_.defaultScene >= 0 ? model_.defaultScene : 0;
    if (size_t(scene) >= model_.scenes.size())
      throw UsageError(file_ + ": scene " + std::to_string(scene) + " does not exist");
    std::vector<std::pair<int, Matrix>> stack;
    for (auto it = model_.scenes[size_t(scene)].nodes.rbegin(); it != model_.scenes[size_t(scene)].nodes.rend(); ++it)
      stack.push_back({*it, kIdentity});
    std::vector<bool> visited(model_.nodes.size(), false);
    while (!stack.empty()) {
      const auto [index, parent] = stack.back();
      stack.pop_back();
      if (index < 0 || size_t(index) >= model_.nodes.size() || visited[size_t(index)])
        throw UsageError(file_ + ": node " + std::to_string(index) + " does not exist or has two parents");
      visited[size_t(index)] = true;
      const tinygltf::Node& node = model_.nodes[size_t(index)];
      const Matrix world = multiply(parent, local_transform(node));
      world_[index] = world;
      if (node.mesh >= 0) add_mesh_node(index, node, world, out);
      for (auto child = node.children.rbegin(); child != node.children.rend(); ++child)
        stack.push_back({*child, world});
    }
  }

  // The node placing the light named `name` (or the node named so, if it places a light).
  LightNode find_light(const std::string& name) const {
    std::vector<int> found;
    for (const auto& [index, world] : world_) {
      const tinygltf::Node& node = model_.nodes[size_t(index)];
      const auto ext = node.extensions.find("KHR_lights_punctual");
      if (ext == node.extensions.end() || !ext->second.Has("light")) continue;
      const int light = ext->second.Get("light").GetNumberAsInt();
      const bool light_named =
          light >= 0 && size_t(light) < model_.lights.size() && model_.lights[size_t(light)].name == name;
      if (light_named || node.name == name) found.push_back(index);
    }
    if (found.empty())
      throw UsageError("LIGHT: no light or light node named \"" + name + "\" in the default scene of " + file_);
    if (found.size() > 1)
      throw UsageError("LIGHT: \"" + name + "\" is placed by " + std::to_string(found.size()) +
                       " nodes; the sample moves one");
    const Matrix& w = world_.at(found[0]);
    return {found[0], {w[12], w[13], w[14]}};
  }

 private:
  void add_mesh_node(int node_index, const tinygltf::Node& node, const Matrix& world, SceneGeometry& out) {
    if (size_t(node.mesh) >= model_.meshes.size())
      throw UsageError(file_ + ": node " + std::to_string(node_index) + ": mesh does not exist");
    const auto instance = instances_.find({node_index, node.mesh});
    const bool lightmapped = instance != instances_.end();
    (lightmapped ? out.lightmapped_instances : out.unlit_instances) += 1;
    const tinygltf::Mesh& mesh = model_.meshes[size_t(node.mesh)];
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      const std::string element = file_ + ": mesh " + std::to_string(node.mesh) + " primitive " + std::to_string(p);
      const tinygltf::Primitive& primitive = mesh.primitives[p];
      const int mode = primitive.mode < 0 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
      if (mode < TINYGLTF_MODE_TRIANGLES || mode > TINYGLTF_MODE_TRIANGLE_FAN)
        continue;  // points and lines: nothing to light
      Draw draw;
      set_material(model_, primitive.material, draw);
      draw.mirrored = determinant3(world) < 0;
      if (lightmapped) {
        draw.lightmapped = true;
        draw.page = instance->second.page;
        std::copy(std::begin(instance->second.scale_offset), std::end(instance->second.scale_offset),
                  draw.scale_offset.begin());
      }
      add_primitive(primitive, element, world, lightmapped, mode, draw, out);
    }
  }

  void add_primitive(const tinygltf::Primitive& primitive, const std::string& element, const Matrix& world,
                     bool lightmapped, int mode, Draw& draw, SceneGeometry& out) {
    const int position_index = attribute(primitive, "POSITION");
    if (position_index < 0) throw UsageError(element + ": has no POSITION");
    const AccessorView positions(model_, position_index, element + " POSITION");
    if (positions.type() != TINYGLTF_TYPE_VEC3 || positions.component_type() != TINYGLTF_COMPONENT_TYPE_FLOAT)
      throw UsageError(element + ": POSITION is not float VEC3");
    const int uv_index = attribute(primitive, "TEXCOORD_1");
    if (lightmapped && uv_index < 0)
      throw UsageError(element +
                       ": has no TEXCOORD_1 (the sample reads lightmap UVs from the glTF, not UVs bake generated)");
    std::optional<AccessorView> uvs;
    if (uv_index >= 0) {
      uvs.emplace(model_, uv_index, element + " TEXCOORD_1");
      const bool integer = uvs->component_type() == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                           uvs->component_type() == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
      if (uvs->type() != TINYGLTF_TYPE_VEC2 ||
          !(uvs->component_type() == TINYGLTF_COMPONENT_TYPE_FLOAT || (integer && uvs->normalized())))
        throw UsageError(element + ": TEXCOORD_1 is not float or normalized unsigned byte/short VEC2");
      if (uvs->count() != positions.count()) throw UsageError(element + ": TEXCOORD_1 and POSITION counts differ");
    }
    std::vector<uint32_t> indices;
    if (primitive.indices >= 0) {
      const AccessorView view(model_, primitive.indices, element + " indices");
      if (view.type() != TINYGLTF_TYPE_SCALAR) throw UsageError(element + ": indices are not SCALAR");
      for (size_t i = 0; i < view.count(); ++i) {
        indices.push_back(view.index(i));
        if (indices.back() >= positions.count())
          throw UsageError(element + ": index " + std::to_string(indices.back()) + " out of range");
      }
    } else {
      for (uint32_t i = 0; i < positions.count(); ++i) indices.push_back(i);
    }
    const std::vector<uint32_t> triangles = triangle_list(mode, indices);
    if (triangles.empty()) return;
    draw.vertex_offset = int32_t(out.vertices.size());
    draw.first_index = uint32_t(out.indices.size());
    draw.index_count = uint32_t(triangles.size());
    for (size_t v = 0; v < positions.count(); ++v) {
      const double x = positions.component(v, 0), y = positions.component(v, 1), z = positions.component(v, 2);
      DrawVertex vertex{};
      for (int r = 0; r < 3; ++r)
        vertex.position[r] =
            float(world[size_t(r)] * x + world[size_t(4 + r)] * y + world[size_t(8 + r)] * z + world[size_t(12 + r)]);
      if (uvs) vertex.lightmap_uv[0] = uvs->component(v, 0), vertex.lightmap_uv[1] = uvs->component(v, 1);
      out.vertices.push_back(vertex);
    }
    out.indices.insert(out.indices.end(), triangles.begin(), triangles.end());
    out.draws.push_back(draw);
  }

  const tinygltf::Model& model_;
  std::string file_;
  std::map<std::pair<int, int>, ExitanceInstanceInfo> instances_;  // (node, mesh) -> the bundle's instance
  std::map<int, Matrix> world_;                                    // nodes of the default scene
};

}  // namespace

SceneGeometry load_scene_geometry(const std::string& gltf_path, const ExitanceBundle* bundle,
                                  const std::string& light) {
  tinygltf::Model model;
  tinygltf::TinyGLTF gltf;
  // Textures are not drawn (baseColorFactor only): leave their images undecoded.
  gltf.SetImageLoader([](tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                         void*) { return true; },
                      nullptr);
  std::string error, warning;
  const bool binary = gltf_path.size() >= 4 && gltf_path.compare(gltf_path.size() - 4, 4, ".glb") == 0;
  const bool loaded = binary ? gltf.LoadBinaryFromFile(&model, &error, &warning, gltf_path)
                             : gltf.LoadASCIIFromFile(&model, &error, &warning, gltf_path);
  if (!loaded) {
    std::string message = error.empty() ? warning : error;
    std::replace(message.begin(), message.end(), '\n', ' ');
    throw UsageError(gltf_path + ": cannot load (" + message + ")");
  }
  SceneGeometry out;
  SceneLoader loader(model, gltf_path, bundle);
  loader.add_scene(out);
  out.light = loader.find_light(light);
  // Lightmapped draws first, by page: one descriptor set bind per page (lightmap_renderer.cpp).
  std::stable_sort(out.draws.begin(), out.draws.end(), [](const Draw& a, const Draw& b) {
    return std::pair(!a.lightmapped, a.page) < std::pair(!b.lightmapped, b.page);
  });
  return out;
}

}  // namespace engine_sample
