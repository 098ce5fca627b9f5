#include "scene_builder.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "light_orientation.h"

namespace exitance::samples {
namespace {

// The float's shortest decimal form as a double, so the JSON says 0.85 rather
// than 0.8500000238418579.
double readable(float value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  double result = 0.0;
  std::from_chars(text, end, result);
  return result;
}

std::vector<double> toDoubles(Vec3 v) { return {readable(v.x), readable(v.y), readable(v.z)}; }

void useExtension(tinygltf::Model& model, const std::string& extension) {
  if (std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), extension) == model.extensionsUsed.end())
    model.extensionsUsed.push_back(extension);
}

}  // namespace

SceneBuilder::SceneBuilder() : model_(std::make_unique<tinygltf::Model>()) {
  model_->asset.version = "2.0";
  model_->asset.generator = "exitance generate_samples";
  model_->buffers.emplace_back();
  model_->scenes.emplace_back();
  model_->defaultScene = 0;
}

SceneBuilder::~SceneBuilder() = default;

MaterialId SceneBuilder::addMaterial(const Material& material) {
  tinygltf::Material gltf;
  gltf.name = material.name;
  gltf.pbrMetallicRoughness.baseColorFactor = toDoubles(material.baseColor);
  gltf.pbrMetallicRoughness.baseColorFactor.push_back(1.0);
  gltf.pbrMetallicRoughness.metallicFactor = readable(material.metallic);
  gltf.pbrMetallicRoughness.roughnessFactor = readable(material.roughness);
  gltf.doubleSided = material.doubleSided;

  // emissiveFactor is clamped to [0,1] by the spec, so a brighter emitter keeps its
  // colour normalised to a peak of 1 and moves the rest into the strength extension.
  const Vec3 radiance = material.emissiveColor * material.emissiveStrength;
  const float peak = std::max({radiance.x, radiance.y, radiance.z});
  if (peak > 1.0f) {
    // Dividing (not multiplying by 1/peak) keeps the peak component exactly 1.
    gltf.emissiveFactor = toDoubles({radiance.x / peak, radiance.y / peak, radiance.z / peak});
    tinygltf::Value::Object strength;
    strength["emissiveStrength"] = tinygltf::Value(readable(peak));
    gltf.extensions["KHR_materials_emissive_strength"] = tinygltf::Value(strength);
    useExtension(*model_, "KHR_materials_emissive_strength");
  } else {
    gltf.emissiveFactor = toDoubles(radiance);
  }
  model_->materials.push_back(std::move(gltf));
  return MaterialId(model_->materials.size() - 1);
}

int SceneBuilder::addAccessor(const void* data, size_t byteLength, size_t count, int componentType, int type,
                              int target) {
  std::vector<unsigned char>& bytes = model_->buffers[0].data;
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = bytes.size();  // every component is 4 bytes, so offsets stay aligned
  view.byteLength = byteLength;
  view.target = target;
  bytes.resize(bytes.size() + byteLength);
  std::memcpy(bytes.data() + view.byteOffset, data, byteLength);
  model_->bufferViews.push_back(view);

  tinygltf::Accessor accessor;
  accessor.bufferView = int(model_->bufferViews.size() - 1);
  accessor.componentType = componentType;
  accessor.count = count;
  accessor.type = type;
  model_->accessors.push_back(accessor);
  return int(model_->accessors.size() - 1);
}

int SceneBuilder::addMeshNode(const std::string& name, const MeshBuilder& mesh, Vec3 translation) {
  return addInstance(name, addMesh(name, mesh), translation);
}

size_t SceneBuilder::meshCount() const { return model_->meshes.size(); }

int SceneBuilder::addMesh(const std::string& name, const MeshBuilder& mesh) {
  size_t triangles = 0;
  tinygltf::Mesh gltfMesh;
  gltfMesh.name = name;
  for (const MeshPrimitiveData& data : mesh.build()) {
    const size_t vertexCount = data.positions.size() / 3;
    auto addFloats = [&](const std::vector<float>& values, int type) {
      return addAccessor(values.data(), values.size() * sizeof(float), vertexCount, TINYGLTF_COMPONENT_TYPE_FLOAT,
                         type, TINYGLTF_TARGET_ARRAY_BUFFER);
    };
    tinygltf::Primitive primitive;
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    primitive.material = data.material;
    primitive.attributes["POSITION"] = addFloats(data.positions, TINYGLTF_TYPE_VEC3);
    primitive.attributes["NORMAL"] = addFloats(data.normals, TINYGLTF_TYPE_VEC3);
    primitive.attributes["TEXCOORD_0"] = addFloats(data.texcoord0, TINYGLTF_TYPE_VEC2);
    primitive.attributes["TEXCOORD_1"] = addFloats(data.texcoord1, TINYGLTF_TYPE_VEC2);
    primitive.indices = addAccessor(data.indices.data(), data.indices.size() * sizeof(std::uint32_t),
                                    data.indices.size(), TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
                                    TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);

    // glTF requires bounds on POSITION.
    tinygltf::Accessor& positions = model_->accessors[size_t(primitive.attributes["POSITION"])];
    positions.minValues.assign(3, std::numeric_limits<double>::max());
    positions.maxValues.assign(3, std::numeric_limits<double>::lowest());
    for (size_t i = 0; i < data.positions.size(); ++i) {
      positions.minValues[i % 3] = std::min(positions.minValues[i % 3], double(data.positions[i]));
      positions.maxValues[i % 3] = std::max(positions.maxValues[i % 3], double(data.positions[i]));
    }
    triangles += data.indices.size() / 3;
    gltfMesh.primitives.push_back(std::move(primitive));
  }
  model_->meshes.push_back(std::move(gltfMesh));
  meshTriangles_.push_back(triangles);
  return int(model_->meshes.size() - 1);
}

int SceneBuilder::addInstance(const std::string& name, int meshIndex, Vec3 translation, float yawRadians) {
  if (meshIndex < 0 || size_t(meshIndex) >= meshTriangles_.size())
    throw std::invalid_argument("instance '" + name + "': no mesh " + std::to_string(meshIndex));
  tinygltf::Node node;
  node.name = name;
  node.mesh = meshIndex;
  if (yawRadians != 0.0f) {
    // Unit quaternion [x, y, z, w] of a turn about +Y.
    const double half = 0.5 * double(yawRadians);
    node.rotation = {0.0, std::sin(half), 0.0, std::cos(half)};
  }
  if (translation != Vec3{}) node.translation = toDoubles(translation);
  triangleCount_ += meshTriangles_[size_t(meshIndex)];
  ++instanceCount_;
  model_->nodes.push_back(std::move(node));
  model_->scenes[0].nodes.push_back(int(model_->nodes.size() - 1));
  return int(model_->nodes.size() - 1);
}

int SceneBuilder::addLightNode(const std::string& name, Vec3 position, const Vec3* pointing, int lightIndex) {
  tinygltf::Node node;
  node.name = name;
  if (position != Vec3{}) node.translation = toDoubles(position);
  if (pointing) {
    const std::array<double, 4> rotation = rotationFromMinusZ(*pointing);
    node.rotation.assign(rotation.begin(), rotation.end());
  }
  tinygltf::Value::Object reference;
  reference["light"] = tinygltf::Value(lightIndex);
  node.extensions["KHR_lights_punctual"] = tinygltf::Value(reference);
  model_->nodes.push_back(std::move(node));
  model_->scenes[0].nodes.push_back(int(model_->nodes.size() - 1));
  return int(model_->nodes.size() - 1);
}

int SceneBuilder::addPointLight(const PointLight& light) {
  tinygltf::Light gltf;
  gltf.name = light.name;
  gltf.type = "point";
  gltf.color = toDoubles(light.color);
  gltf.intensity = readable(light.intensity);
  model_->lights.push_back(std::move(gltf));
  return addLightNode(light.name, light.position, nullptr, int(model_->lights.size() - 1));
}

int SceneBuilder::addSpotLight(const SpotLight& light) {
  if (!(light.innerConeAngle >= 0.0f && light.innerConeAngle < light.outerConeAngle &&
        light.outerConeAngle <= 1.5707963f))
    throw std::invalid_argument("spot light '" + light.name + "': need 0 ≤ inner < outer ≤ π/2");
  tinygltf::Light gltf;
  gltf.name = light.name;
  gltf.type = "spot";
  gltf.color = toDoubles(light.color);
  gltf.intensity = readable(light.intensity);
  gltf.spot.innerConeAngle = readable(light.innerConeAngle);
  gltf.spot.outerConeAngle = readable(light.outerConeAngle);
  model_->lights.push_back(std::move(gltf));
  return addLightNode(light.name, light.position, &light.direction, int(model_->lights.size() - 1));
}

int SceneBuilder::addDirectionalLight(const DirectionalLight& light) {
  tinygltf::Light gltf;
  gltf.name = light.name;
  gltf.type = "directional";
  gltf.color = toDoubles(light.color);
  gltf.intensity = readable(light.intensity);
  model_->lights.push_back(std::move(gltf));
  return addLightNode(light.name, {}, &light.direction, int(model_->lights.size() - 1));
}

void SceneBuilder::write(const std::string& path) const {
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToFile(model_.get(), path, /*embedImages=*/false, /*embedBuffers=*/false,
                                   /*prettyPrint=*/true, /*writeBinary=*/false))
    throw std::runtime_error("cannot write " + path);
}

}  // namespace exitance::samples
