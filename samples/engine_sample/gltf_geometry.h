// The scene as an engine loads it: the glTF's default scene flattened into world-space triangles,
// one draw per triangle primitive, each matched to its lightmap in the bundle (page, scale_offset).
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "exitance/loader/exitance_loader.h"

namespace engine_sample {

struct DrawVertex {
  float position[3];     // world space
  float lightmap_uv[2];  // TEXCOORD_1 as stored (the page UV is computed per draw from scale_offset)
};

struct Draw {
  uint32_t first_index = 0, index_count = 0;
  int32_t vertex_offset = 0;
  std::array<float, 3> albedo{};    // clamp(baseColorFactor x (1 - metallicFactor), 0, 1), as bake reads it
  std::array<float, 3> emission{};  // emissiveFactor x emissiveStrength
  bool double_sided = false;
  bool mirrored = false;     // world matrix with a negative determinant: the front face winds clockwise
  bool lightmapped = false;  // the bundle has an instance for this (node, mesh)
  uint32_t page = 0;
  std::array<float, 4> scale_offset{1, 1, 0, 0};  // page UV = TEXCOORD_1 * (s0, s1) + (s2, s3)
};

// The node that places the light the sample moves.
struct LightNode {
  int node = -1;
  std::array<double, 3> world_position{};  // as the glTF places it (the bundle's baked position)
};

struct SceneGeometry {
  std::vector<DrawVertex> vertices;
  std::vector<uint32_t> indices;  // triangle lists (strips and fans converted as bake's importer does)
  std::vector<Draw> draws;        // sorted by page, lightmapped first
  LightNode light;
  size_t lightmapped_instances = 0, unlit_instances = 0;
};

// Loads `gltf_path` (throws UsageError for a file the sample cannot draw, naming the element), matches
// its mesh nodes with `bundle`'s instances by glTF node and mesh index, and finds `light`: a
// KHR_lights_punctual light's name or the name of the node placing it, placed exactly once.
SceneGeometry load_scene_geometry(const std::string& gltf_path, const ExitanceBundle* bundle, const std::string& light);

}  // namespace engine_sample
