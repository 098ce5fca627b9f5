// A glTF scene with lightmap UV seams: a smooth UV sphere (radius 1, centre 1.2 m up) over a 6 m
// floor, neither with TEXCOORD_1, so the bake generates their UVs (charts cut the sphere). Lit by
// the --sky the caller gives and, with `sun`, a directional light (3 W/m^2, from 40° above the
// horizon) whose terminator and shadow cross the sphere's seams. Written with its buffer inline
// (a data: URI).
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/base64.h"

namespace exitance::test {

inline void write_sphere_over_floor_gltf(const std::string& path, int segments = 48, int rings = 24,
                                         bool sun = false) {
  const double pi = 3.14159265358979323846;
  struct Mesh {
    std::vector<float> positions, normals;
    std::vector<uint32_t> indices;
  };
  Mesh sphere, floor;
  for (int j = 0; j <= rings; ++j)
    for (int i = 0; i <= segments; ++i) {
      const double theta = pi * double(j) / rings, phi = 2 * pi * double(i) / segments;
      const float n[3] = {float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
                          float(-std::sin(theta) * std::sin(phi))};
      sphere.positions.insert(sphere.positions.end(), {n[0], n[1] + 1.2f, n[2]});
      sphere.normals.insert(sphere.normals.end(), {n[0], n[1], n[2]});
    }
  auto at = [&](int i, int j) { return uint32_t(j * (segments + 1) + i); };
  for (int j = 0; j < rings; ++j)
    for (int i = 0; i < segments; ++i)  // counter-clockwise seen from outside
      sphere.indices.insert(sphere.indices.end(),
                            {at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i + 1, j)});
  floor.positions = {-3, 0, -3, -3, 0, 3, 3, 0, 3, 3, 0, -3};
  floor.normals = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
  floor.indices = {0, 1, 2, 0, 2, 3};

  std::vector<uint8_t> buffer;
  nlohmann::json views = nlohmann::json::array(), accessors = nlohmann::json::array(), meshes = nlohmann::json::array();
  auto append = [&](const void* data, size_t bytes, int target) {
    while (buffer.size() % 4) buffer.push_back(0);
    views.push_back({{"buffer", 0}, {"byteOffset", buffer.size()}, {"byteLength", bytes}, {"target", target}});
    buffer.insert(buffer.end(), static_cast<const uint8_t*>(data), static_cast<const uint8_t*>(data) + bytes);
    return views.size() - 1;
  };
  for (const Mesh* mesh : {&sphere, &floor}) {
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (size_t k = 0; k < mesh->positions.size(); ++k)
      lo[k % 3] = std::min(lo[k % 3], mesh->positions[k]), hi[k % 3] = std::max(hi[k % 3], mesh->positions[k]);
    const size_t vertices = mesh->positions.size() / 3;
    accessors.push_back({{"bufferView", append(mesh->positions.data(), mesh->positions.size() * 4, 34962)},
                         {"componentType", 5126}, {"count", vertices}, {"type", "VEC3"},
                         {"min", {lo[0], lo[1], lo[2]}}, {"max", {hi[0], hi[1], hi[2]}}});
    accessors.push_back({{"bufferView", append(mesh->normals.data(), mesh->normals.size() * 4, 34962)},
                         {"componentType", 5126}, {"count", vertices}, {"type", "VEC3"}});
    accessors.push_back({{"bufferView", append(mesh->indices.data(), mesh->indices.size() * 4, 34963)},
                         {"componentType", 5125}, {"count", mesh->indices.size()}, {"type", "SCALAR"}});
    const size_t first = accessors.size() - 3;
    nlohmann::json primitive = {{"attributes", {{"POSITION", first}, {"NORMAL", first + 1}}},
                                {"indices", first + 2}, {"material", 0}};
    meshes.push_back({{"name", mesh == &sphere ? "Sphere" : "Floor"}, {"primitives", nlohmann::json::array({primitive})}});
  }
  using json = nlohmann::json;
  json gltf;
  gltf["asset"] = {{"version", "2.0"}};
  gltf["scene"] = 0;
  gltf["scenes"] = json::array({json{{"nodes", {0, 1}}}});
  gltf["nodes"] = json::array({json{{"mesh", 0}, {"name", "Sphere"}}, json{{"mesh", 1}, {"name", "Floor"}}});
  gltf["meshes"] = meshes;
  if (sun) {
    // A glTF light shines along its node's -Z: rotate -Z onto the sun's direction d.
    const double e = 40 * pi / 180, a = 30 * pi / 180;
    const double d[3] = {-std::cos(e) * std::cos(a), -std::sin(e), -std::cos(e) * std::sin(a)};
    const double axis[3] = {d[1], -d[0], 0};  // cross((0,0,-1), d)
    const double axis_length = std::hypot(axis[0], axis[1]), angle = std::acos(-d[2]);
    const double s = std::sin(angle / 2) / axis_length;
    gltf["extensionsUsed"] = {"KHR_lights_punctual"};
    gltf["extensions"]["KHR_lights_punctual"]["lights"] =
        json::array({json{{"type", "directional"}, {"color", {1.0, 1.0, 1.0}}, {"intensity", 3.0}}});
    gltf["nodes"].push_back({{"name", "Sun"},
                             {"rotation", {axis[0] * s, axis[1] * s, axis[2] * s, std::cos(angle / 2)}},
                             {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    gltf["scenes"][0]["nodes"].push_back(2);
  }
  json pbr = {{"baseColorFactor", {0.8, 0.8, 0.8, 1.0}}, {"metallicFactor", 0.0}};
  gltf["materials"] = json::array({json{{"pbrMetallicRoughness", pbr}}});
  gltf["accessors"] = accessors;
  gltf["bufferViews"] = views;
  gltf["buffers"] = json::array(
      {json{{"byteLength", buffer.size()}, {"uri", "data:application/octet-stream;base64," + base64(buffer)}}});
  std::ofstream(path) << gltf.dump(1);
}

}  // namespace exitance::test
