// scene_builder_selftest: checks the builder's geometric pieces on their own.
// Prints each failed check and exits 1 if any failed.
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <vector>

#include "light_orientation.h"
#include "lightmap_chart_packer.h"
#include "mesh_builder.h"

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

}  // namespace

int main() {
  lightRotationsTurnMinusZOntoTheDirection();
  axisAlignedQuadsFaceTheirNormal();
  openingPiecesCoverTheQuadMinusTheHole();
  boxesFaceInOrOut();
  packedChartsAreDisjointAndScaledAlike();
  std::printf(failures ? "%d checks failed\n" : "all checks passed\n", failures);
  return failures ? 1 : 0;
}
