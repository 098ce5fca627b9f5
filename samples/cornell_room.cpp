// The classic Cornell box, scaled to a 4 m room: red left wall, green right wall,
// white elsewhere, two boxes turned by ±17°, one square ceiling light.
#include <numbers>

#include "sample_scenes.h"

namespace exitance::samples {

void buildCornellRoom(SceneBuilder& scene) {
  const MaterialId white = scene.addMaterial({.name = "White", .baseColor = {0.73f, 0.73f, 0.73f}});
  const MaterialId red = scene.addMaterial({.name = "Red", .baseColor = {0.63f, 0.065f, 0.05f}});
  const MaterialId green = scene.addMaterial({.name = "Green", .baseColor = {0.14f, 0.45f, 0.091f}});
  const MaterialId light = scene.addMaterial({.name = "CeilingLight",
                                              .baseColor = {0.78f, 0.78f, 0.78f},
                                              .emissiveColor = {1.0f, 0.85f, 0.6f},
                                              .emissiveStrength = 20.0f});

  const float r = 2.0f, top = 4.0f;
  auto wall = [&](const char* name, Quad quad, MaterialId material) {
    MeshBuilder mesh;
    mesh.addQuad(quad, material);
    scene.addMeshNode(name, mesh);
  };
  // Every wall faces into the room.
  wall("Floor", Quad::axisAligned({-r, 0, -r}, {r, 0, r}, {0, 1, 0}), white);
  wall("BackWall", Quad::axisAligned({-r, 0, -r}, {r, top, -r}, {0, 0, 1}), white);
  wall("FrontWall", Quad::axisAligned({-r, 0, r}, {r, top, r}, {0, 0, -1}), white);
  wall("LeftWall", Quad::axisAligned({-r, 0, -r}, {-r, top, r}, {1, 0, 0}), red);
  wall("RightWall", Quad::axisAligned({r, 0, -r}, {r, top, r}, {-1, 0, 0}), green);

  // The panel fills a hole cut in the ceiling: flush, watertight, never coplanar
  // with the ceiling surface.
  const float halfPanel = 0.5f;
  const Quad ceiling = Quad::axisAligned({-r, top, -r}, {r, top, r}, {0, -1, 0});
  MeshBuilder ceilingMesh;
  ceilingMesh.addQuadWithOpening(
      ceiling, {r - halfPanel, r + halfPanel, r - halfPanel, r + halfPanel}, white);
  scene.addMeshNode("Ceiling", ceilingMesh);
  wall("CeilingLight", Quad::axisAligned({-halfPanel, top, -halfPanel}, {halfPanel, top, halfPanel}, {0, -1, 0}),
       light);

  // Box geometry is centred on the node, which stands the box on the floor.
  const float yaw = 17.0f * std::numbers::pi_v<float> / 180.0f;
  MeshBuilder tallBox, shortBox;
  tallBox.addBox({.center = {0, 1.2f, 0}, .size = {1.2f, 2.4f, 1.2f}, .yawRadians = yaw}, white,
                 FaceDirection::Outward, BoxFace::AllButBottom);
  shortBox.addBox({.center = {0, 0.6f, 0}, .size = {1.2f, 1.2f, 1.2f}, .yawRadians = -yaw}, white,
                  FaceDirection::Outward, BoxFace::AllButBottom);
  scene.addMeshNode("TallBox", tallBox, {-0.7f, 0.0f, -0.6f});
  scene.addMeshNode("ShortBox", shortBox, {0.7f, 0.0f, 0.65f});
}

}  // namespace exitance::samples
