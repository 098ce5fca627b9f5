// Accumulates materials, meshes on nodes and KHR_lights_punctual lights, and
// writes them as a glTF 2.0 file (.gltf + external .bin) through tinygltf.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mesh_builder.h"
#include "vec3.h"

namespace tinygltf {
struct Model;
}

namespace exitance::samples {

struct Material {
  std::string name;
  Vec3 baseColor{0.73f, 0.73f, 0.73f};  // linear albedo
  float metallic = 0.0f;                // 0 for the diffuse sample scenes
  float roughness = 1.0f;
  // Emitted radiance is emissiveColor × emissiveStrength. The writer splits it into
  // an emissiveFactor ≤ 1 and KHR_materials_emissive_strength when it exceeds 1.
  Vec3 emissiveColor{0.0f, 0.0f, 0.0f};
  float emissiveStrength = 1.0f;
  bool doubleSided = false;
};

// KHR_lights_punctual lights. Intensities are W/sr (point, spot) and W/m² (directional).
struct PointLight {
  std::string name;
  Vec3 position;
  Vec3 color{1.0f, 1.0f, 1.0f};
  float intensity = 1.0f;
};

struct SpotLight {
  std::string name;
  Vec3 position;
  Vec3 direction{0.0f, -1.0f, 0.0f};  // where the cone points; need not be unit length
  Vec3 color{1.0f, 1.0f, 1.0f};
  float intensity = 1.0f;
  float innerConeAngle = 0.0f;           // radians from the axis
  float outerConeAngle = 0.7853981634f;  // radians, π/4 is glTF's default
};

struct DirectionalLight {
  std::string name;
  Vec3 direction{0.0f, -1.0f, 0.0f};  // direction the light travels
  Vec3 color{1.0f, 1.0f, 1.0f};
  float intensity = 1.0f;
};

class SceneBuilder {
 public:
  SceneBuilder();
  ~SceneBuilder();
  SceneBuilder(const SceneBuilder&) = delete;
  SceneBuilder& operator=(const SceneBuilder&) = delete;

  MaterialId addMaterial(const Material& material);

  // Builds `mesh` (lightmap layout included) into a glTF mesh on its own node called
  // `name`, translated by `translation`. Returns the node index.
  int addMeshNode(const std::string& name, const MeshBuilder& mesh, Vec3 translation = {});

  // Builds `mesh` into a glTF mesh without placing it; returns the mesh index for addInstance.
  int addMesh(const std::string& name, const MeshBuilder& mesh);
  // A node showing mesh `meshIndex` (from addMesh), turned by `yawRadians` about +Y and then
  // translated. Several nodes may share a mesh: each is an instance with its own lightmap
  // rectangle in the baker, all sharing the mesh's TEXCOORD_1 layout. Returns the node index.
  int addInstance(const std::string& name, int meshIndex, Vec3 translation = {}, float yawRadians = 0.0f);

  int addPointLight(const PointLight& light);
  int addSpotLight(const SpotLight& light);
  int addDirectionalLight(const DirectionalLight& light);

  // Triangles as the baker sees them: every instance of a mesh counts.
  size_t triangleCount() const { return triangleCount_; }
  size_t instanceCount() const { return instanceCount_; }
  size_t meshCount() const;

  // Writes `path` (.gltf) and its buffer next to it (same stem, .bin).
  // Throws std::runtime_error when tinygltf cannot write.
  void write(const std::string& path) const;

 private:
  int addAccessor(const void* data, size_t byteLength, size_t count, int componentType, int type, int target);
  int addLightNode(const std::string& name, Vec3 position, const Vec3* pointing, int lightIndex);

  std::unique_ptr<tinygltf::Model> model_;
  std::vector<size_t> meshTriangles_;  // per glTF mesh
  size_t triangleCount_ = 0;
  size_t instanceCount_ = 0;
};

}  // namespace exitance::samples
