// scene_builder_selftest: checks the builder's geometric pieces on their own.
// Prints each failed check and exits 1 if any failed.
#include <tiny_gltf.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "light_orientation.h"
#include "lightmap_chart_packer.h"
#include "mesh_builder.h"
#include "scene_builder.h"

using namespace exitance::samples;

namespace {

int failures = 0;

void expect(bool condition, const char* what) {
  if (!condition) {
    std::printf("FAILED: %s\n", what);
    ++failures;
  }
}

bool near(Vec3 a, Vec3 b) { return length(a - b) < 1e-5f; }

Vec3 rotate(const std::array<double, 4>& q, Vec3 v) {
  const Vec3 u{float(q[0]), float(q[1]), float(q[2])};
  const Vec3 t = 2.0f * cross(u, v);
  return v + float(q[3]) * t + cross(u, t);
}

void lightRotationsTurnMinusZOntoTheDirection() {
  for (Vec3 direction : {Vec3{0, -1, 0}, Vec3{0, 0, 1}, Vec3{0, 0, -1}, Vec3{1, -2.65f, 0.7f}, Vec3{-3, 1, 2}})
    expect(near(rotate(rotationFromMinusZ(direction), {0, 0, -1}), normalize(direction)),
           "rotationFromMinusZ turns -Z onto the direction");
}

void axisAlignedQuadsFaceTheirNormal() {
  for (Vec3 normal : {Vec3{1, 0, 0}, Vec3{-1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, -1, 0}, Vec3{0, 0, 1}, Vec3{0, 0, -1}}) {
    const Vec3 far = Vec3{2, 3, 4} - Vec3{std::abs(normal.x) * 2, std::abs(normal.y) * 3, std::abs(normal.z) * 4};
    expect(near(Quad::axisAligned({0, 0, 0}, far, normal).frontNormal(), normal), "Quad::axisAligned faces its normal");
  }
}

void openingPiecesCoverTheQuadMinusTheHole() {
  const Quad wall{{0, 0, 0}, {5, 0, 0}, {0, 2.8f, 0}};
  float area = 0.0f;
  for (const Quad& piece : quadAroundOpening(wall, {1.0f, 1.9f, 0.0f, 2.1f})) {
    area += length(cross(piece.edgeU, piece.edgeV));
    expect(near(piece.frontNormal(), wall.frontNormal()), "opening pieces keep the quad's facing");
  }
  expect(std::abs(area - (5 * 2.8f - 0.9f * 2.1f)) < 1e-4f, "opening pieces cover the quad minus the hole");
}

void boxesFaceInOrOut() {
  for (FaceDirection direction : {FaceDirection::Outward, FaceDirection::Inward}) {
    MeshBuilder mesh;
    mesh.addBox({.center = {1, 2, 3}, .size = {1, 2, 3}, .yawRadians = 0.3f}, 0, direction);
    for (const MeshPrimitiveData& data : mesh.build())
      for (size_t v = 0; v < data.positions.size() / 3; ++v) {
        const Vec3 fromCenter = Vec3{data.positions[3 * v], data.positions[3 * v + 1], data.positions[3 * v + 2]} -
                                Vec3{1, 2, 3};
        const Vec3 normal{data.normals[3 * v], data.normals[3 * v + 1], data.normals[3 * v + 2]};
        expect((dot(fromCenter, normal) > 0) == (direction == FaceDirection::Outward), "box faces point the chosen way");
      }
  }
}

void packedChartsAreDisjointAndScaledAlike() {
  std::mt19937 engine(7);
  std::vector<ChartSize> charts;
  for (int i = 0; i < 150; ++i) charts.push_back({0.1f + float(engine() % 500) / 100, 0.1f + float(engine() % 300) / 100});
  const std::vector<PlacedChart> placed = packLightmapCharts(charts);
  verifyChartsDisjoint(placed);  // throws on failure
  const float scale0 = std::max(placed[0].width, placed[0].height) / std::max(charts[0].width, charts[0].height);
  for (size_t i = 0; i < charts.size(); ++i) {
    const float scale = std::max(placed[i].width, placed[i].height) / std::max(charts[i].width, charts[i].height);
    expect(std::abs(scale - scale0) < 1e-4f * scale0, "every chart gets the same texel density");
  }
  bool threw = false;
  try {
    packLightmapCharts(std::vector<ChartSize>(2000, ChartSize{1, 1}));
  } catch (const std::runtime_error&) {
    threw = true;
  }
  expect(threw, "too many charts for the padding is an error, not an overlap");
}

// Two coplanar pieces sharing an edge and a third folded up from it: one chart, shared
// corners written once, and every edge as long in TEXCOORD_1 (over the chart's scale)
// as in space.
void panelsShareCornersAndKeepTheirSize() {
  const Vec3 a{0, 0, 0}, b{2, 0, 0}, c{3, 0, 0}, d{0, 0, -1}, e{2, 0, -1}, f{3, 0, -1}, g{0, 1, -1}, h{3, 1, -1};
  MeshBuilder mesh;
  mesh.addPanel({{{a, b, e, d}, 0, 0, 2, 1, 0}, {{b, c, f, e}, 2, 0, 3, 1, 0}, {{d, f, h, g}, 0, 1, 3, 2, 0}});
  const std::vector<MeshPrimitiveData> primitives = mesh.build();
  expect(primitives.size() == 1 && primitives[0].indices.size() == 18, "a panel gives two triangles per piece");
  if (primitives.size() != 1) return;
  const MeshPrimitiveData& p = primitives[0];
  // a b c d e f shared by the flat pieces (6), the fold's d f are new vertices (other normal), g h.
  expect(p.positions.size() / 3 == 10, "corners shared by coplanar pieces are one vertex");
  float scale = -1.0f;
  bool isometric = true;
  for (size_t t = 0; t < p.indices.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t i = p.indices[t + size_t(k)], j = p.indices[t + size_t((k + 1) % 3)];
      const float world = length(Vec3{p.positions[3 * i], p.positions[3 * i + 1], p.positions[3 * i + 2]} -
                                 Vec3{p.positions[3 * j], p.positions[3 * j + 1], p.positions[3 * j + 2]});
      const float uv = std::hypot(p.texcoord1[2 * i] - p.texcoord1[2 * j], p.texcoord1[2 * i + 1] - p.texcoord1[2 * j + 1]);
      if (scale < 0.0f) scale = uv / world;
      isometric = isometric && std::abs(uv / world - scale) < 1e-4f * scale;
    }
  expect(isometric, "a panel keeps one texel density over all its pieces");
  bool threw = false;
  try {
    MeshBuilder wrong;
    wrong.addPanel({{{a, b, e, d}, 0, 0, 3, 1, 0}});  // rectangle 3 m wide for a 2 m piece
  } catch (const std::invalid_argument&) {
    threw = true;
  }
  expect(threw, "a panel piece whose rectangle is not its size is refused");
}

// One mesh on two nodes: written once, referenced by both, the second turned about +Y.
void meshesCanBeInstancedOnSeveralNodes() {
  SceneBuilder scene;
  const MaterialId grey = scene.addMaterial({.name = "Grey"});
  MeshBuilder box;
  box.addBox({.center = {0, 1, 0}, .size = {2, 2, 1}}, grey, FaceDirection::Outward, BoxFace::AllButBottom);
  const int mesh = scene.addMesh("Box", box);
  const float yaw = 0.5f * 3.14159265f;
  scene.addInstance("First", mesh, {5, 0, 0});
  scene.addInstance("Second", mesh, {-5, 0, 0}, yaw);
  expect(scene.instanceCount() == 2 && scene.meshCount() == 1 && scene.triangleCount() == 2 * 10,
         "instances count the shared mesh's triangles once each");

  const std::filesystem::path directory =
      std::filesystem::temp_directory_path() / ("scene_builder_selftest_" + std::to_string(std::random_device{}()));
  std::filesystem::create_directories(directory);
  const std::string file = (directory / "instances.gltf").string();
  scene.write(file);
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  std::string error, warning;
  const bool loaded = loader.LoadASCIIFromFile(&model, &error, &warning, file);
  std::filesystem::remove_all(directory);
  expect(loaded, "the instanced scene loads back");
  if (!loaded) return;
  expect(model.meshes.size() == 1, "a shared mesh is written once");
  int users = 0;
  const tinygltf::Node* turned = nullptr;
  for (const tinygltf::Node& node : model.nodes)
    if (node.mesh == 0) {
      ++users;
      if (node.name == "Second") turned = &node;
    }
  expect(users == 2, "both nodes reference the shared mesh");
  expect(turned && turned->rotation.size() == 4, "the turned instance has a rotation");
  if (turned && turned->rotation.size() == 4) {
    const std::array<double, 4> q{turned->rotation[0], turned->rotation[1], turned->rotation[2], turned->rotation[3]};
    expect(near(rotate(q, {1, 0, 0}), rotateAboutY({1, 0, 0}, yaw)), "the node's rotation is the yaw about +Y");
  }
}

}  // namespace

int main() {
  lightRotationsTurnMinusZOntoTheDirection();
  axisAlignedQuadsFaceTheirNormal();
  openingPiecesCoverTheQuadMinusTheHole();
  boxesFaceInOrOut();
  packedChartsAreDisjointAndScaledAlike();
  panelsShareCornersAndKeepTheirSize();
  meshesCanBeInstancedOnSeveralNodes();
  std::printf(failures ? "%d checks failed\n" : "all checks passed\n", failures);
  return failures ? 1 : 0;
}
