// The "Veach ajar" situation: a closed 4 m room lit only through a 5 cm gap of a door
// left ajar, by a bright panel in a small closed antechamber outside it. Unguided path
// tracing finds the light only through the gap, so this is the scene guiding must win on.
#include "sample_scenes.h"

namespace exitance::samples {

void buildAjarRoom(SceneBuilder& scene) {
  const MaterialId white = scene.addMaterial({.name = "White", .baseColor = {0.75f, 0.75f, 0.75f}});
  const MaterialId wood = scene.addMaterial({.name = "Door", .baseColor = {0.45f, 0.3f, 0.2f}});
  const MaterialId light = scene.addMaterial({.name = "Panel",
                                              .baseColor = {0.0f, 0.0f, 0.0f},
                                              .emissiveColor = {1.0f, 0.95f, 0.85f},
                                              .emissiveStrength = 200.0f});
  const float r = 2.0f, top = 3.0f;
  auto quad = [&](const char* name, Quad q, MaterialId material) {
    MeshBuilder mesh;
    mesh.addQuad(q, material);
    scene.addMeshNode(name, mesh);
  };
  // Main room x,z in [-2, 2], inward faces. The wall at x = +2 has a doorway 1 m wide, 2 m high.
  quad("Floor", Quad::axisAligned({-r, 0, -r}, {r, 0, r}, {0, 1, 0}), white);
  quad("Ceiling", Quad::axisAligned({-r, top, -r}, {r, top, r}, {0, -1, 0}), white);
  quad("BackWall", Quad::axisAligned({-r, 0, -r}, {r, top, -r}, {0, 0, 1}), white);
  quad("FrontWall", Quad::axisAligned({-r, 0, r}, {r, top, r}, {0, 0, -1}), white);
  quad("LeftWall", Quad::axisAligned({-r, 0, -r}, {-r, top, r}, {1, 0, 0}), white);
  MeshBuilder doorWall;
  const Quad rightWall = Quad::axisAligned({r, 0, -r}, {r, top, r}, {-1, 0, 0});
  doorWall.addQuadWithOpening(rightWall, {1.5f, 2.5f, 0.0f, 2.0f}, white);
  scene.addMeshNode("DoorWall", doorWall);
  // The door: a 1 m x 2 m slab in the doorway, closed except for a 5 cm gap along one edge.
  MeshBuilder door;
  door.addBox({.center = {r, 1.0f, 0.025f}, .size = {0.04f, 2.0f, 0.95f}}, wood, FaceDirection::Outward);
  scene.addMeshNode("Door", door);
  // Antechamber x in [2, 3], z in [-1, 1], closed, with the panel on its far wall.
  const float x1 = 3.0f;
  quad("AnteFloor", Quad::axisAligned({r, 0, -1}, {x1, 0, 1}, {0, 1, 0}), white);
  quad("AnteCeiling", Quad::axisAligned({r, 2.2f, -1}, {x1, 2.2f, 1}, {0, -1, 0}), white);
  quad("AnteBack", Quad::axisAligned({r, 0, -1}, {x1, 2.2f, -1}, {0, 0, 1}), white);
  quad("AnteFront", Quad::axisAligned({r, 0, 1}, {x1, 2.2f, 1}, {0, 0, -1}), white);
  quad("AnteFar", Quad::axisAligned({x1, 0, -1}, {x1, 2.2f, 1}, {-1, 0, 0}), white);
  quad("Panel", Quad::axisAligned({x1 - 0.01f, 0.6f, -0.4f}, {x1 - 0.01f, 1.6f, 0.4f}, {-1, 0, 0}), light);
  // The room's own wall above the doorway closes the antechamber's top edge (2.0 .. 2.2 m).
  quad("AnteLintel", Quad::axisAligned({r, 2.0f, -1}, {r, 2.2f, 1}, {1, 0, 0}), white);
}

}  // namespace exitance::samples
