// An open 20 m courtyard ringed by buildings of different heights, with a low
// wall across it, lit by a low sun. Most of its light comes from the sky, which
// the baker takes from `--sky`.
#include <cmath>
#include <numbers>

#include "sample_scenes.h"

namespace exitance::samples {

void buildCourtyard(SceneBuilder& scene) {
  const MaterialId paving = scene.addMaterial({.name = "Paving", .baseColor = {0.45f, 0.42f, 0.38f}});
  const MaterialId plaster = scene.addMaterial({.name = "Plaster", .baseColor = {0.75f, 0.70f, 0.62f}});
  const MaterialId brick = scene.addMaterial({.name = "Brick", .baseColor = {0.55f, 0.25f, 0.18f}});
  const MaterialId stone = scene.addMaterial({.name = "Stone", .baseColor = {0.60f, 0.60f, 0.58f}});

  // 1 m cells give vertex-lit previews some shading detail on the large faces.
  MeshBuilder ground(1.0f);
  ground.addQuad(Quad::axisAligned({-10, 0, -10}, {10, 0, 10}, {0, 1, 0}), paving);
  scene.addMeshNode("Ground", ground);

  // Buildings are modelled around their node so the file exercises translated instances.
  struct Building {
    const char* name;
    Vec3 position;  // centre of the footprint, on the ground
    Vec3 size;
    MaterialId material;
  };
  const Building buildings[] = {
      {"NorthHall", {-1.0f, 0, -8.0f}, {12.0f, 9.0f, 4.0f}, plaster},
      {"WestTower", {-8.0f, 0, -1.5f}, {4.0f, 14.0f, 5.0f}, brick},
      {"EastWing", {8.0f, 0, -2.0f}, {4.0f, 6.0f, 8.0f}, plaster},
      {"SouthHouse", {-5.0f, 0, 8.0f}, {6.0f, 4.5f, 4.0f}, brick},
      {"Pavilion", {6.5f, 0, 7.0f}, {3.0f, 3.0f, 3.0f}, stone},
  };
  for (const Building& building : buildings) {
    MeshBuilder mesh(1.0f);
    mesh.addBox({.center = {0, building.size.y / 2, 0}, .size = building.size}, building.material,
                 FaceDirection::Outward, BoxFace::AllButBottom);
    scene.addMeshNode(building.name, mesh, building.position);
  }

  MeshBuilder lowWall(1.0f);
  lowWall.addBox({.center = {0, 0.5f, 0}, .size = {8.0f, 1.0f, 0.3f}, .yawRadians = 0.2f}, stone,
                 FaceDirection::Outward, BoxFace::AllButBottom);
  scene.addMeshNode("LowWall", lowWall, {1.0f, 0.0f, 2.0f});

  // Sun 40° above the horizon from azimuth 35° (off every axis), so shadows fall diagonally.
  const float elevation = 40.0f * std::numbers::pi_v<float> / 180.0f;
  const float azimuth = 35.0f * std::numbers::pi_v<float> / 180.0f;
  const Vec3 towardsSun{std::cos(elevation) * std::sin(azimuth), std::sin(elevation),
                        std::cos(elevation) * std::cos(azimuth)};
  scene.addDirectionalLight({.name = "Sun", .direction = -towardsSun, .color = {1.0f, 0.95f, 0.85f}, .intensity = 3.0f});
}

}  // namespace exitance::samples
