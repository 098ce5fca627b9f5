// A three-storey office block: each storey a 4×4 grid of furnished rooms joined
// by doorways, inside a plain outer shell. Rooms are lit by emissive ceiling
// panels, point lights or tilted spot lights, so the scene has many emitters and
// light that reaches most rooms only through doors. Every surface is tessellated
// to 20 cm cells, which puts the scene past 200 000 triangles.
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "sample_scenes.h"

namespace exitance::samples {
namespace {

constexpr int kStoreys = 3, kRoomsPerSide = 4;
constexpr float kRoomSize = 5.0f, kWallThickness = 0.2f;
constexpr float kStoreyHeight = 3.0f, kCeilingHeight = 2.8f;
constexpr float kDoorWidth = 0.9f, kDoorHeight = 2.1f;
constexpr float kRoomPitch = kRoomSize + kWallThickness;
constexpr float kBuildingWidth = kWallThickness + kRoomsPerSide * kRoomPitch;
constexpr float kCellSize = 0.2f;
constexpr float kPanelSize = 1.0f;

// Fixed-seed generator mapped to floats by hand: std::uniform_real_distribution
// differs between standard libraries, the raw mt19937 sequence does not.
class DeterministicRandom {
 public:
  explicit DeterministicRandom(std::uint32_t seed) : engine_(seed) {}
  float uniform(float low, float high) { return low + (high - low) * float(engine_() >> 8) / float(1u << 24); }
  int below(int count) { return int(engine_() % std::uint32_t(count)); }

 private:
  std::mt19937 engine_;
};

struct Materials {
  MaterialId wall, floor, ceiling, wood, fabric, laminate, warmPanel, coolPanel, facade, roof;
};

struct RoomBounds {
  float x0, x1, y0, y1, z0, z1;
  Vec3 center(float y) const { return {(x0 + x1) / 2, y, (z0 + z1) / 2}; }
};

RoomBounds roomBounds(int storey, int i, int j) {
  const float x0 = kWallThickness + float(i) * kRoomPitch, z0 = kWallThickness + float(j) * kRoomPitch;
  const float y0 = float(storey) * kStoreyHeight;
  return {x0, x0 + kRoomSize, y0, y0 + kCeilingHeight, z0, z0 + kRoomSize};
}

// Door centres along each interior wall, chosen once so both rooms cut the same hole.
// eastDoor[s][i][j]: z of the door between rooms (i,j) and (i+1,j);
// southDoor[s][i][j]: x of the door between rooms (i,j) and (i,j+1).
struct DoorLayout {
  float eastDoor[kStoreys][kRoomsPerSide][kRoomsPerSide];
  float southDoor[kStoreys][kRoomsPerSide][kRoomsPerSide];
};

DoorLayout chooseDoors(DeterministicRandom& random) {
  DoorLayout doors{};
  const float margin = 0.4f + kDoorWidth / 2;  // keep doors clear of the room corners
  for (int s = 0; s < kStoreys; ++s)
    for (int i = 0; i < kRoomsPerSide; ++i)
      for (int j = 0; j < kRoomsPerSide; ++j) {
        const RoomBounds room = roomBounds(s, i, j);
        doors.eastDoor[s][i][j] = random.uniform(room.z0 + margin, room.z1 - margin);
        doors.southDoor[s][i][j] = random.uniform(room.x0 + margin, room.x1 - margin);
      }
  return doors;
}

// An inward-facing wall from `start` along `along`, full room height, with an
// optional doorway centred at world coordinate `doorCenter` along the wall.
void addWall(MeshBuilder& mesh, MaterialId material, Vec3 start, Vec3 along, const float* doorCenter) {
  const Quad wall{start, along, {0, kCeilingHeight, 0}};
  if (!doorCenter) {
    mesh.addQuad(wall, material);
    return;
  }
  // Distance along the wall from `start` to the door centre; walls run along x or z.
  const bool runsAlongX = along.x != 0.0f;
  const float axisSign = (runsAlongX ? along.x : along.z) > 0.0f ? 1.0f : -1.0f;
  const float doorAlong = (*doorCenter - (runsAlongX ? start.x : start.z)) * axisSign;
  mesh.addQuadWithOpening(
      wall, {doorAlong - kDoorWidth / 2, doorAlong + kDoorWidth / 2, 0.0f, kDoorHeight}, material);
}

// The reveal of a doorway through the wall slab: two jambs, the lintel's underside and
// the threshold. `low`/`high` are opposite corners of the opening's box in the wall.
void addDoorReveal(MeshBuilder& mesh, MaterialId wall, MaterialId floor, Vec3 low, Vec3 high, bool wallAlongZ) {
  if (wallAlongZ) {  // opening spans z, wall thickness spans x
    mesh.addQuad(Quad::axisAligned(low, {high.x, high.y, low.z}, {0, 0, 1}), wall);
    mesh.addQuad(Quad::axisAligned({low.x, low.y, high.z}, high, {0, 0, -1}), wall);
  } else {  // opening spans x, wall thickness spans z
    mesh.addQuad(Quad::axisAligned(low, {low.x, high.y, high.z}, {1, 0, 0}), wall);
    mesh.addQuad(Quad::axisAligned({high.x, low.y, low.z}, high, {-1, 0, 0}), wall);
  }
  mesh.addQuad(Quad::axisAligned({low.x, high.y, low.z}, high, {0, -1, 0}), wall);
  mesh.addQuad(Quad::axisAligned(low, {high.x, low.y, high.z}, {0, 1, 0}), floor);
}

// Two to four pieces of furniture standing on the floor, kept apart from each
// other and from the walls so no surfaces interpenetrate.
void addFurniture(MeshBuilder& mesh, const Materials& materials, const RoomBounds& room, DeterministicRandom& random) {
  struct Piece {
    Vec3 size;
    MaterialId material;
  };
  const std::array<Piece, 6> catalogue = {{
      {{1.4f, 0.75f, 0.8f}, materials.wood},      // table
      {{1.0f, 1.9f, 0.5f}, materials.laminate},   // cabinet
      {{2.0f, 0.8f, 0.9f}, materials.fabric},     // sofa
      {{0.4f, 1.6f, 1.2f}, materials.wood},       // shelf
      {{0.6f, 0.6f, 0.6f}, materials.laminate},   // crate
      {{1.6f, 0.45f, 2.0f}, materials.fabric},    // bed
  }};
  struct Placed {
    float x, z, radius;
  };
  std::vector<Placed> placed;
  const int wanted = 2 + random.below(3);
  for (int attempt = 0; attempt < 50 && int(placed.size()) < wanted; ++attempt) {
    const Piece& piece = catalogue[size_t(random.below(int(catalogue.size())))];
    // The footprint's half diagonal bounds the piece at any yaw.
    const float radius = 0.5f * std::hypot(piece.size.x, piece.size.z);
    const float clearance = 0.1f;
    const float x = random.uniform(room.x0 + radius + clearance, room.x1 - radius - clearance);
    const float z = random.uniform(room.z0 + radius + clearance, room.z1 - radius - clearance);
    const float yaw = random.uniform(-0.6f, 0.6f);
    bool clear = true;
    for (const Placed& other : placed)
      clear = clear && std::hypot(x - other.x, z - other.z) > radius + other.radius + clearance;
    if (!clear) continue;
    placed.push_back({x, z, radius});
    mesh.addBox({.center = {x, room.y0 + piece.size.y / 2, z}, .size = piece.size, .yawRadians = yaw}, piece.material,
                FaceDirection::Outward, BoxFace::AllButBottom);
  }
}

enum class RoomLight { WarmPanel, CoolPanel, Point, Spot };

void addRoom(SceneBuilder& scene, const Materials& materials, const DoorLayout& doors, int s, int i, int j,
             RoomLight light, DeterministicRandom& random) {
  const RoomBounds r = roomBounds(s, i, j);
  const std::string name = "Room_" + std::to_string(s) + "_" + std::to_string(i) + "_" + std::to_string(j);
  MeshBuilder mesh(kCellSize);

  mesh.addQuad(Quad::axisAligned({r.x0, r.y0, r.z0}, {r.x1, r.y0, r.z1}, {0, 1, 0}), materials.floor);

  // Walls face inward; a wall shared with a neighbour gets that neighbour's doorway.
  const float* west = i > 0 ? &doors.eastDoor[s][i - 1][j] : nullptr;
  const float* east = i + 1 < kRoomsPerSide ? &doors.eastDoor[s][i][j] : nullptr;
  const float* north = j > 0 ? &doors.southDoor[s][i][j - 1] : nullptr;
  const float* south = j + 1 < kRoomsPerSide ? &doors.southDoor[s][i][j] : nullptr;
  addWall(mesh, materials.wall, {r.x0, r.y0, r.z1}, {0, 0, -kRoomSize}, west);
  addWall(mesh, materials.wall, {r.x1, r.y0, r.z0}, {0, 0, kRoomSize}, east);
  addWall(mesh, materials.wall, {r.x0, r.y0, r.z0}, {kRoomSize, 0, 0}, north);
  addWall(mesh, materials.wall, {r.x1, r.y0, r.z1}, {-kRoomSize, 0, 0}, south);
  // This room owns the reveals of its east and south doorways.
  if (east)
    addDoorReveal(mesh, materials.wall, materials.floor, {r.x1, r.y0, *east - kDoorWidth / 2},
                  {r.x1 + kWallThickness, r.y0 + kDoorHeight, *east + kDoorWidth / 2}, true);
  if (south)
    addDoorReveal(mesh, materials.wall, materials.floor, {*south - kDoorWidth / 2, r.y0, r.z1},
                  {*south + kDoorWidth / 2, r.y0 + kDoorHeight, r.z1 + kWallThickness}, false);

  const Quad ceiling = Quad::axisAligned({r.x0, r.y1, r.z0}, {r.x1, r.y1, r.z1}, {0, -1, 0});
  const Vec3 c = r.center(r.y1);
  switch (light) {
    case RoomLight::WarmPanel:
    case RoomLight::CoolPanel: {
      // The panel fills a hole in the ceiling rather than overlapping it.
      const float h = kPanelSize / 2, mid = kRoomSize / 2;
      mesh.addQuadWithOpening(ceiling, {mid - h, mid + h, mid - h, mid + h}, materials.ceiling);
      mesh.addQuad(Quad::axisAligned({c.x - h, c.y, c.z - h}, {c.x + h, c.y, c.z + h}, {0, -1, 0}),
                   light == RoomLight::WarmPanel ? materials.warmPanel : materials.coolPanel);
      break;
    }
    case RoomLight::Point:
      mesh.addQuad(ceiling, materials.ceiling);
      scene.addPointLight(
          {.name = name + "_Point", .position = r.center(r.y0 + 2.2f), .color = {1.0f, 0.8f, 0.6f}, .intensity = 4.0f});
      break;
    case RoomLight::Spot:
      mesh.addQuad(ceiling, materials.ceiling);
      // Tilted towards a corner so the spot's rotation is not axis aligned.
      scene.addSpotLight({.name = name + "_Spot",
                          .position = r.center(r.y1 - 0.15f),
                          .direction = {1.0f, -2.65f, 0.7f},
                          .color = {1.0f, 0.95f, 0.9f},
                          .intensity = 15.0f,
                          .innerConeAngle = 0.35f,
                          .outerConeAngle = 0.6f});
      break;
  }

  addFurniture(mesh, materials, r, random);
  scene.addMeshNode(name, mesh);
}

}  // namespace

void buildBuilding(SceneBuilder& scene) {
  const Materials materials{
      .wall = scene.addMaterial({.name = "WallPaint", .baseColor = {0.75f, 0.74f, 0.70f}}),
      .floor = scene.addMaterial({.name = "FloorBoards", .baseColor = {0.42f, 0.30f, 0.20f}}),
      .ceiling = scene.addMaterial({.name = "CeilingPaint", .baseColor = {0.82f, 0.82f, 0.82f}}),
      .wood = scene.addMaterial({.name = "Wood", .baseColor = {0.45f, 0.30f, 0.18f}}),
      .fabric = scene.addMaterial({.name = "Fabric", .baseColor = {0.20f, 0.30f, 0.55f}}),
      .laminate = scene.addMaterial({.name = "Laminate", .baseColor = {0.80f, 0.80f, 0.78f}}),
      .warmPanel = scene.addMaterial({.name = "WarmPanel",
                                      .baseColor = {0.8f, 0.8f, 0.8f},
                                      .emissiveColor = {1.0f, 0.85f, 0.6f},
                                      .emissiveStrength = 12.0f}),
      .coolPanel = scene.addMaterial({.name = "CoolPanel",
                                      .baseColor = {0.8f, 0.8f, 0.8f},
                                      .emissiveColor = {0.85f, 0.92f, 1.0f},
                                      .emissiveStrength = 12.0f}),
      .facade = scene.addMaterial({.name = "Facade", .baseColor = {0.62f, 0.58f, 0.52f}}),
      .roof = scene.addMaterial({.name = "Roof", .baseColor = {0.25f, 0.25f, 0.27f}}),
  };

  DeterministicRandom random(20240611u);
  const DoorLayout doors = chooseDoors(random);
  for (int s = 0; s < kStoreys; ++s)
    for (int j = 0; j < kRoomsPerSide; ++j)
      for (int i = 0; i < kRoomsPerSide; ++i) {
        // Three rooms in five get a panel, the others a point or a spot light.
        const int roomIndex = (s * kRoomsPerSide + j) * kRoomsPerSide + i;
        const RoomLight light = roomIndex % 5 == 3   ? RoomLight::Point
                                : roomIndex % 5 == 4 ? RoomLight::Spot
                                : roomIndex % 2 == 0 ? RoomLight::WarmPanel
                                                     : RoomLight::CoolPanel;
        addRoom(scene, materials, doors, s, i, j, light, random);
      }

  // Outer shell: outward walls and a roof; the ground-floor slab sits on nothing.
  const float height = kStoreys * kStoreyHeight;
  const Box shell{.center = {kBuildingWidth / 2, height / 2, kBuildingWidth / 2},
                  .size = {kBuildingWidth, height, kBuildingWidth}};
  MeshBuilder facade(0.5f);
  facade.addBox(shell, materials.facade, FaceDirection::Outward, BoxFace::AllButBottom & ~BoxFace::PosY);
  facade.addBox(shell, materials.roof, FaceDirection::Outward, BoxFace::PosY);
  scene.addMeshNode("Shell", facade);
}

}  // namespace exitance::samples
