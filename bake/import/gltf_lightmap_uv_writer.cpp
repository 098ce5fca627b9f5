#include "exitance/bake/import/gltf_lightmap_uv_writer.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <tuple>

#include "exitance/bake/import/gltf_accessor_reader.h"
#include "exitance/bake/import/gltf_file_load.h"
#include "exitance/bake/import/gltf_triangle_corners.h"
#include "exitance/bake/input_error.h"

namespace exitance {
namespace {

constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

int components_of(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    default: return 0;
  }
}

int type_of(int components) {
  return components == 1 ? TINYGLTF_TYPE_SCALAR
                         : (components == 2 ? TINYGLTF_TYPE_VEC2
                                            : (components == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC4));
}

// New accessors go into one new buffer, each in a bufferView of its own.
class AccessorAppender {
 public:
  explicit AccessorAppender(tinygltf::Model& model) : model_(model), buffer_(int(model.buffers.size())) {
    model_.buffers.emplace_back();
  }

  // `values` holds count * components floats, written as floats or (JOINTS) unsigned shorts.
  int add_attribute(const std::vector<float>& values, int components, bool as_unsigned_short, bool with_bounds) {
    const size_t count = values.size() / size_t(components);
    std::vector<uint8_t> bytes;
    if (as_unsigned_short) {
      for (float v : values) {
        const uint16_t x = uint16_t(std::clamp(v, 0.0f, 65535.0f));
        bytes.insert(bytes.end(), reinterpret_cast<const uint8_t*>(&x), reinterpret_cast<const uint8_t*>(&x) + 2);
      }
    } else {
      bytes.resize(values.size() * sizeof(float));
      std::memcpy(bytes.data(), values.data(), bytes.size());
    }
    tinygltf::Accessor accessor;
    accessor.bufferView = add_view(bytes, kArrayBuffer);
    accessor.componentType = as_unsigned_short ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_FLOAT;
    accessor.count = count;
    accessor.type = type_of(components);
    if (with_bounds && count > 0) {
      accessor.minValues.assign(size_t(components), 1e300);
      accessor.maxValues.assign(size_t(components), -1e300);
      for (size_t i = 0; i < count; ++i)
        for (size_t k = 0; k < size_t(components); ++k) {
          accessor.minValues[k] = std::min(accessor.minValues[k], double(values[i * size_t(components) + k]));
          accessor.maxValues[k] = std::max(accessor.maxValues[k], double(values[i * size_t(components) + k]));
        }
    }
    model_.accessors.push_back(std::move(accessor));
    return int(model_.accessors.size() - 1);
  }

  int add_indices(const std::vector<uint32_t>& indices, uint32_t vertex_count) {
    std::vector<uint8_t> bytes;
    const bool short_indices = vertex_count <= 65535;
    for (uint32_t i : indices) {
      if (short_indices) {
        const uint16_t x = uint16_t(i);
        bytes.insert(bytes.end(), reinterpret_cast<const uint8_t*>(&x), reinterpret_cast<const uint8_t*>(&x) + 2);
      } else {
        bytes.insert(bytes.end(), reinterpret_cast<const uint8_t*>(&i), reinterpret_cast<const uint8_t*>(&i) + 4);
      }
    }
    tinygltf::Accessor accessor;
    accessor.bufferView = add_view(bytes, kElementArrayBuffer);
    accessor.componentType =
        short_indices ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    accessor.count = indices.size();
    accessor.type = TINYGLTF_TYPE_SCALAR;
    model_.accessors.push_back(std::move(accessor));
    return int(model_.accessors.size() - 1);
  }

 private:
  int add_view(const std::vector<uint8_t>& bytes, int target) {
    std::vector<unsigned char>& data = model_.buffers[size_t(buffer_)].data;
    data.resize((data.size() + 3) / 4 * 4, 0);  // 4-byte alignment for every component type
    tinygltf::BufferView view;
    view.buffer = buffer_;
    view.byteOffset = data.size();
    view.byteLength = bytes.size();
    view.target = target;
    data.insert(data.end(), bytes.begin(), bytes.end());
    model_.bufferViews.push_back(std::move(view));
    return int(model_.bufferViews.size() - 1);
  }

  tinygltf::Model& model_;
  int buffer_;
};

// Every attribute of the primitive (or of one morph target), remapped to the new vertices.
std::map<std::string, int> remapped_attributes(const tinygltf::Model& model, const std::map<std::string, int>& attributes,
                                               const std::vector<uint32_t>& source_vertex, AccessorAppender& appender,
                                               const std::string& file, bool morph_target) {
  std::map<std::string, int> out;
  for (const auto& [name, accessor_index] : attributes) {
    if (accessor_index < 0 || size_t(accessor_index) >= model.accessors.size())
      throw InputError(file, "accessor " + std::to_string(accessor_index), "does not exist");
    const int components = components_of(model.accessors[size_t(accessor_index)].type);
    if (!components) throw InputError(file, "accessor " + std::to_string(accessor_index), "is not a vertex attribute type");
    const std::vector<float> values = read_accessor_floats(model, accessor_index, components, file, name, NonFinite::Keep);
    std::vector<float> remapped(source_vertex.size() * size_t(components));
    for (size_t v = 0; v < source_vertex.size(); ++v)
      for (size_t k = 0; k < size_t(components); ++k)
        remapped[v * size_t(components) + k] = values[size_t(source_vertex[v]) * size_t(components) + k];
    const bool joints = !morph_target && name.rfind("JOINTS_", 0) == 0;
    out[name] = appender.add_attribute(remapped, components, joints, name == "POSITION");
  }
  return out;
}

}  // namespace

void write_gltf_with_lightmap_uvs(const std::string& input, const std::string& output, int uv_set,
                                  const std::vector<MeshLightmapUvs>& meshes, Diagnostics& diagnostics) {
  const std::filesystem::path out_path(output);
  if (out_path.extension() != ".gltf") throw InputError(output, "--write-gltf", "the file name must end in .gltf");
  tinygltf::Model model = load_gltf_model(input, diagnostics);
  AccessorAppender appender(model);
  const std::string uv_name = "TEXCOORD_" + std::to_string(uv_set);
  for (const MeshLightmapUvs& generated : meshes) {
    if (generated.mesh < 0 || size_t(generated.mesh) >= model.meshes.size()) continue;
    size_t corner = 0;  // into generated.corner_uv, across the mesh's triangle primitives
    for (tinygltf::Primitive& primitive : model.meshes[size_t(generated.mesh)].primitives) {
      const int mode = primitive.mode < 0 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
      if (mode <= TINYGLTF_MODE_LINE_STRIP || mode > TINYGLTF_MODE_TRIANGLE_FAN) continue;
      const auto position = primitive.attributes.find("POSITION");
      if (position == primitive.attributes.end()) continue;
      const size_t vertex_count = model.accessors.at(size_t(position->second)).count;
      std::vector<uint32_t> indices;
      if (primitive.indices >= 0) {
        indices = read_accessor_indices(model, primitive.indices, input);
      } else {
        indices.resize(vertex_count);
        for (size_t i = 0; i < vertex_count; ++i) indices[i] = uint32_t(i);
      }
      const std::vector<uint32_t> corners = triangle_corners(mode, indices);
      if (corner + corners.size() > generated.corner_uv.size())
        throw std::runtime_error("--write-gltf: mesh " + std::to_string(generated.mesh) +
                                 " has more triangles than its generated UVs");
      // A new vertex per (source vertex, generated UV): split exactly at the chart seams.
      std::map<std::tuple<uint32_t, uint32_t, uint32_t>, uint32_t> vertex_of;
      std::vector<uint32_t> source_vertex, new_indices;
      std::vector<float> uvs;
      for (size_t c = 0; c < corners.size(); ++c) {
        const Vec2 uv = generated.corner_uv[corner + c];
        const auto key = std::tuple{corners[c], std::bit_cast<uint32_t>(uv.x), std::bit_cast<uint32_t>(uv.y)};
        auto [it, inserted] = vertex_of.emplace(key, uint32_t(source_vertex.size()));
        if (inserted) {
          source_vertex.push_back(corners[c]);
          uvs.insert(uvs.end(), {uv.x, uv.y});
        }
        new_indices.push_back(it->second);
      }
      corner += corners.size();
      std::map<std::string, int> attributes = primitive.attributes;
      attributes.erase(uv_name);
      attributes = remapped_attributes(model, attributes, source_vertex, appender, input, false);
      const int uv_accessor = appender.add_attribute(uvs, 2, false, false);
      attributes[uv_name] = uv_accessor;
      if (uv_set == 1 && !attributes.count("TEXCOORD_0")) attributes["TEXCOORD_0"] = uv_accessor;
      for (auto& target : primitive.targets) target = remapped_attributes(model, target, source_vertex, appender, input, true);
      primitive.attributes = std::move(attributes);
      primitive.indices = appender.add_indices(new_indices, uint32_t(source_vertex.size()));
      primitive.mode = TINYGLTF_MODE_TRIANGLES;
    }
  }
  tinygltf::TinyGLTF writer;
  // Images stay as the input references them (a URI, a data URI or a bufferView): nothing is decoded.
  writer.SetImageWriter(
      [](const std::string*, const std::string*, const tinygltf::Image* image, bool, std::string* out_uri, void*) {
        *out_uri = image->uri;
        return true;
      },
      nullptr);
  std::error_code error;
  if (out_path.has_parent_path()) std::filesystem::create_directories(out_path.parent_path(), error);
  const std::filesystem::path temporary = out_path.string() + ".tmp";
  if (!writer.WriteGltfSceneToFile(&model, temporary.string(), false, true, true, false))
    throw std::runtime_error("--write-gltf: could not write " + temporary.string());
  std::filesystem::rename(temporary, out_path, error);
  if (error) throw std::runtime_error("--write-gltf: could not rename to " + output + ": " + error.message());
}

}  // namespace exitance
