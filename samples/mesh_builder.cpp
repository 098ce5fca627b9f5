#include "mesh_builder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include "lightmap_chart_packer.h"

namespace exitance::samples {
namespace {

float component(Vec3 v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }

Vec3 unitAxis(int axis) {
  return {axis == 0 ? 1.0f : 0.0f, axis == 1 ? 1.0f : 0.0f, axis == 2 ? 1.0f : 0.0f};
}

int cellsForLength(float length, float maxEdgeLength) {
  if (maxEdgeLength <= 0.0f) return 1;
  return std::max(1, static_cast<int>(std::ceil(length / maxEdgeLength - 1e-4f)));
}

// Every triangle's geometric normal (from its counter-clockwise winding) must agree
// with the NORMAL attribute, or single-sided surfaces would face the wrong way.
void verifyWindingMatchesNormals(const MeshPrimitiveData& primitive) {
  auto position = [&](std::uint32_t i) {
    return Vec3{primitive.positions[3 * i], primitive.positions[3 * i + 1], primitive.positions[3 * i + 2]};
  };
  for (size_t t = 0; t + 2 < primitive.indices.size(); t += 3) {
    const std::uint32_t i0 = primitive.indices[t], i1 = primitive.indices[t + 1], i2 = primitive.indices[t + 2];
    const Vec3 geometric = cross(position(i1) - position(i0), position(i2) - position(i0));
    const Vec3 normal{primitive.normals[3 * i0], primitive.normals[3 * i0 + 1], primitive.normals[3 * i0 + 2]};
    if (!(dot(geometric, normal) > 0.0f))
      throw std::logic_error("mesh builder: triangle " + std::to_string(t / 3) + " winds against its normal");
  }
}

}  // namespace

Quad Quad::axisAligned(Vec3 corner0, Vec3 corner1, Vec3 frontNormal) {
  int flatAxis = -1;
  for (int axis = 0; axis < 3; ++axis)
    if (std::abs(component(frontNormal, axis)) == 1.0f) flatAxis = axis;
  if (flatAxis < 0 || component(corner0, flatAxis) != component(corner1, flatAxis))
    throw std::invalid_argument("Quad::axisAligned: normal must be an axis and the corners must share it");
  // Cyclic axis order makes cross(edgeU, edgeV) point along +flatAxis.
  const int axisU = (flatAxis + 1) % 3, axisV = (flatAxis + 2) % 3;
  const Vec3 low{std::min(corner0.x, corner1.x), std::min(corner0.y, corner1.y), std::min(corner0.z, corner1.z)};
  const Quad positive{low,
                      unitAxis(axisU) * std::abs(component(corner1, axisU) - component(corner0, axisU)),
                      unitAxis(axisV) * std::abs(component(corner1, axisV) - component(corner0, axisV))};
  return component(frontNormal, flatAxis) > 0.0f ? positive : positive.flipped();
}

std::vector<Quad> quadAroundOpening(const Quad& quad, const Opening& opening) {
  const float lengthU = length(quad.edgeU), lengthV = length(quad.edgeV);
  const Vec3 alongU = quad.edgeU * (1.0f / lengthU), alongV = quad.edgeV * (1.0f / lengthV);
  const float u0 = std::clamp(opening.uMin, 0.0f, lengthU), u1 = std::clamp(opening.uMax, u0, lengthU);
  const float v0 = std::clamp(opening.vMin, 0.0f, lengthV), v1 = std::clamp(opening.vMax, v0, lengthV);
  const Quad pieces[] = {
      {quad.origin, quad.edgeU, alongV * v0},                                       // below
      {quad.origin + alongV * v1, quad.edgeU, alongV * (lengthV - v1)},             // above
      {quad.origin + alongV * v0, alongU * u0, alongV * (v1 - v0)},                 // left
      {quad.origin + alongU * u1 + alongV * v0, alongU * (lengthU - u1), alongV * (v1 - v0)},  // right
  };
  constexpr float kMinimumExtent = 1e-4f;  // skip slivers left when the hole touches an edge
  std::vector<Quad> kept;
  for (const Quad& piece : pieces)
    if (length(piece.edgeU) > kMinimumExtent && length(piece.edgeV) > kMinimumExtent) kept.push_back(piece);
  return kept;
}

void MeshBuilder::addQuad(const Quad& quad, MaterialId material) {
  addQuad(quad, material,
          {cellsForLength(length(quad.edgeU), maxEdgeLength_), cellsForLength(length(quad.edgeV), maxEdgeLength_)});
}

void MeshBuilder::addQuad(const Quad& quad, MaterialId material, QuadGrid grid) {
  if (grid.cellsU < 1 || grid.cellsV < 1) throw std::invalid_argument("MeshBuilder::addQuad: empty grid");
  if (!(length(cross(quad.edgeU, quad.edgeV)) > 0.0f)) throw std::invalid_argument("MeshBuilder::addQuad: degenerate quad");
  charts_.push_back({quad, material, grid});
}

void MeshBuilder::addQuadWithOpening(const Quad& quad, const Opening& opening, MaterialId material) {
  for (const Quad& piece : quadAroundOpening(quad, opening)) addQuad(piece, material);
}

void MeshBuilder::addBox(const Box& box, MaterialId material, FaceDirection direction, std::uint8_t faces) {
  const Vec3 h = box.size * 0.5f;
  // Box-local faces with outward normals, edgeV pointing up on the side faces.
  const struct {
    std::uint8_t face;
    Quad quad;
  } sides[] = {
      {BoxFace::PosX, {{h.x, -h.y, h.z}, {0, 0, -2 * h.z}, {0, 2 * h.y, 0}}},
      {BoxFace::NegX, {{-h.x, -h.y, -h.z}, {0, 0, 2 * h.z}, {0, 2 * h.y, 0}}},
      {BoxFace::PosZ, {{-h.x, -h.y, h.z}, {2 * h.x, 0, 0}, {0, 2 * h.y, 0}}},
      {BoxFace::NegZ, {{h.x, -h.y, -h.z}, {-2 * h.x, 0, 0}, {0, 2 * h.y, 0}}},
      {BoxFace::PosY, {{-h.x, h.y, h.z}, {2 * h.x, 0, 0}, {0, 0, -2 * h.z}}},
      {BoxFace::NegY, {{-h.x, -h.y, -h.z}, {2 * h.x, 0, 0}, {0, 0, 2 * h.z}}},
  };
  for (const auto& side : sides) {
    if (!(faces & side.face)) continue;
    const Quad outward{box.center + rotateAboutY(side.quad.origin, box.yawRadians),
                       rotateAboutY(side.quad.edgeU, box.yawRadians), rotateAboutY(side.quad.edgeV, box.yawRadians)};
    addQuad(direction == FaceDirection::Outward ? outward : outward.flipped(), material);
  }
}

void MeshBuilder::addPanel(std::vector<PanelPiece> pieces) {
  if (pieces.empty()) throw std::invalid_argument("MeshBuilder::addPanel: no pieces");
  for (const PanelPiece& piece : pieces) {
    const std::array<Vec3, 4>& c = piece.corners;
    const float width = piece.s1 - piece.s0, height = piece.t1 - piece.t0;
    // A relative tolerance: the generator's corners carry float rounding.
    auto sameLength = [](float a, float b) { return std::abs(a - b) <= 1e-4f * std::max(1.0f, b); };
    if (piece.s0 < 0.0f || piece.t0 < 0.0f || !(width > 0.0f) || !(height > 0.0f))
      throw std::invalid_argument("MeshBuilder::addPanel: piece rectangle empty or below (0, 0)");
    if (!sameLength(length(c[1] - c[0]), width) || !sameLength(length(c[2] - c[3]), width) ||
        !sameLength(length(c[3] - c[0]), height) || !sameLength(length(c[2] - c[1]), height))
      throw std::invalid_argument("MeshBuilder::addPanel: piece corners do not match its rectangle");
  }
  panels_.push_back(std::move(pieces));
}

namespace {

ChartSize panelExtent(const std::vector<PanelPiece>& pieces) {
  ChartSize extent;
  for (const PanelPiece& piece : pieces) {
    extent.width = std::max(extent.width, piece.s1);
    extent.height = std::max(extent.height, piece.t1);
  }
  return extent;
}

MeshPrimitiveData& primitiveFor(std::vector<MeshPrimitiveData>& primitives, MaterialId material) {
  auto found = std::find_if(primitives.begin(), primitives.end(),
                            [&](const MeshPrimitiveData& p) { return p.material == material; });
  MeshPrimitiveData& primitive = found != primitives.end() ? *found : primitives.emplace_back();
  primitive.material = material;
  return primitive;
}

using PanelVertexKey = std::pair<MaterialId, std::array<float, 10>>;

// Emits a panel's pieces; a corner equal in position, normal and both UVs to one
// already emitted in the same primitive reuses its vertex.
void emitPanel(const std::vector<PanelPiece>& pieces, const ChartSize& extent, const PlacedChart& place,
               std::vector<MeshPrimitiveData>& primitives, std::map<PanelVertexKey, std::uint32_t>& vertexIndex) {
  for (const PanelPiece& piece : pieces) {
    MeshPrimitiveData& primitive = primitiveFor(primitives, piece.material);
    const Vec3 normal = normalize(cross(piece.corners[1] - piece.corners[0], piece.corners[3] - piece.corners[0]));
    const std::array<float, 2> local[4] = {
        {piece.s0, piece.t0}, {piece.s1, piece.t0}, {piece.s1, piece.t1}, {piece.s0, piece.t1}};
    std::uint32_t index[4];
    for (int k = 0; k < 4; ++k) {
      const Vec3 p = piece.corners[size_t(k)];
      const float s = local[k][0] / extent.width, t = local[k][1] / extent.height;
      // Same turn convention as the quad charts: rotated by 90°, never mirrored.
      const std::array<float, 2> uv1 = place.turned
                                           ? std::array<float, 2>{place.x + t * place.width, place.y + (1.0f - s) * place.height}
                                           : std::array<float, 2>{place.x + s * place.width, place.y + t * place.height};
      const std::array<float, 10> key{p.x, p.y, p.z, normal.x, normal.y, normal.z, local[k][0], local[k][1], uv1[0], uv1[1]};
      const auto inserted = vertexIndex.try_emplace({piece.material, key}, std::uint32_t(primitive.positions.size() / 3));
      if (inserted.second) {
        primitive.positions.insert(primitive.positions.end(), {p.x, p.y, p.z});
        primitive.normals.insert(primitive.normals.end(), {normal.x, normal.y, normal.z});
        primitive.texcoord0.insert(primitive.texcoord0.end(), local[k].begin(), local[k].end());
        primitive.texcoord1.insert(primitive.texcoord1.end(), uv1.begin(), uv1.end());
      }
      index[k] = inserted.first->second;
    }
    primitive.indices.insert(primitive.indices.end(), {index[0], index[1], index[2], index[0], index[2], index[3]});
  }
}

}  // namespace

std::vector<MeshPrimitiveData> MeshBuilder::build() const {
  std::vector<ChartSize> sizes;
  for (const Chart& chart : charts_) sizes.push_back({length(chart.quad.edgeU), length(chart.quad.edgeV)});
  for (const std::vector<PanelPiece>& panel : panels_) sizes.push_back(panelExtent(panel));
  const std::vector<PlacedChart> placements = packLightmapCharts(sizes);

  std::vector<MeshPrimitiveData> primitives;
  for (size_t c = 0; c < charts_.size(); ++c) {
    const Chart& chart = charts_[c];
    const PlacedChart& place = placements[c];
    MeshPrimitiveData& primitive = primitiveFor(primitives, chart.material);

    const Vec3 normal = chart.quad.frontNormal();
    const float lengthU = length(chart.quad.edgeU), lengthV = length(chart.quad.edgeV);
    const auto base = static_cast<std::uint32_t>(primitive.positions.size() / 3);
    const int columns = chart.grid.cellsU + 1;
    for (int b = 0; b <= chart.grid.cellsV; ++b) {
      for (int a = 0; a <= chart.grid.cellsU; ++a) {
        const float s = float(a) / float(chart.grid.cellsU), t = float(b) / float(chart.grid.cellsV);
        const Vec3 p = chart.quad.origin + chart.quad.edgeU * s + chart.quad.edgeV * t;
        primitive.positions.insert(primitive.positions.end(), {p.x, p.y, p.z});
        primitive.normals.insert(primitive.normals.end(), {normal.x, normal.y, normal.z});
        primitive.texcoord0.insert(primitive.texcoord0.end(), {s * lengthU, t * lengthV});
        // A turned chart is rotated by 90° (not mirrored) so its UV winding matches the others.
        if (place.turned)
          primitive.texcoord1.insert(primitive.texcoord1.end(),
                                     {place.x + t * place.width, place.y + (1.0f - s) * place.height});
        else
          primitive.texcoord1.insert(primitive.texcoord1.end(), {place.x + s * place.width, place.y + t * place.height});
      }
    }
    for (int b = 0; b < chart.grid.cellsV; ++b) {
      for (int a = 0; a < chart.grid.cellsU; ++a) {
        const std::uint32_t v00 = base + std::uint32_t(b * columns + a), v10 = v00 + 1;
        const std::uint32_t v01 = v00 + std::uint32_t(columns), v11 = v01 + 1;
        primitive.indices.insert(primitive.indices.end(), {v00, v10, v11, v00, v11, v01});
      }
    }
  }
  std::map<PanelVertexKey, std::uint32_t> panelVertices;
  for (size_t p = 0; p < panels_.size(); ++p)
    emitPanel(panels_[p], sizes[charts_.size() + p], placements[charts_.size() + p], primitives, panelVertices);
  for (const MeshPrimitiveData& primitive : primitives) verifyWindingMatchesNormals(primitive);
  return primitives;
}

}  // namespace exitance::samples
