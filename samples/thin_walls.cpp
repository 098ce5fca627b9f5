// Two rooms sharing a wall 5 mm thick (1/10 of a texel at the default 20 texels/m bench
// density): the left room is lit, the right one must stay black. Measures light leaks.
#include "sample_scenes.h"

namespace exitance::samples {

void buildThinWalls(SceneBuilder& scene) {
  const MaterialId white = scene.addMaterial({.name = "White", .baseColor = {0.8f, 0.8f, 0.8f}});
  const MaterialId light = scene.addMaterial({.name = "Panel",
                                              .baseColor = {0.0f, 0.0f, 0.0f},
                                              .emissiveColor = {1.0f, 1.0f, 1.0f},
                                              .emissiveStrength = 20.0f});
  const float thickness = 0.005f, size = 2.0f;
  for (int room = 0; room < 2; ++room) {
    const float x0 = room == 0 ? 0.0f : size + thickness;
    MeshBuilder mesh;
    mesh.addBox({.center = {x0 + size / 2, size / 2, size / 2}, .size = {size, size, size}}, white,
                FaceDirection::Inward);
    scene.addMeshNode(room == 0 ? "LitRoom" : "DarkRoom", mesh);
  }
  MeshBuilder panel;
  panel.addQuad(Quad::axisAligned({0.5f, size - 0.01f, 0.5f}, {1.5f, size - 0.01f, 1.5f}, {0, -1, 0}), light);
  scene.addMeshNode("Panel", panel);
}

}  // namespace exitance::samples
