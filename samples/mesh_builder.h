// Collects a mesh as planar quads (each one lightmap chart), then produces the
// per-material triangle lists with POSITION, NORMAL, TEXCOORD_0 and a packed
// TEXCOORD_1 lightmap layout.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "vec3.h"

namespace exitance::samples {

using MaterialId = int;

// A planar parallelogram: corners origin, origin+edgeU, origin+edgeU+edgeV, origin+edgeV.
// Its front face is on the side of cross(edgeU, edgeV); the corners run
// counter-clockwise seen from there, as glTF expects.
struct Quad {
  Vec3 origin;
  Vec3 edgeU;
  Vec3 edgeV;

  Vec3 frontNormal() const { return normalize(cross(edgeU, edgeV)); }
  Quad flipped() const { return {origin, edgeV, edgeU}; }

  // The axis-aligned rectangle spanned by two opposite corners that share one
  // coordinate, facing along `frontNormal` (which must be ±X, ±Y or ±Z).
  static Quad axisAligned(Vec3 corner0, Vec3 corner1, Vec3 frontNormal);
};

// A hole in a quad, in metres along edgeU and edgeV from the quad's origin.
struct Opening {
  float uMin = 0.0f, uMax = 0.0f;
  float vMin = 0.0f, vMax = 0.0f;
};

// The up to four quads covering `quad` minus `opening`: full-width strips below and
// above the hole, and the pieces left and right of it. Empty pieces are left out.
std::vector<Quad> quadAroundOpening(const Quad& quad, const Opening& opening);

// A box of `size` centred on `center`, turned by `yawRadians` about its vertical axis.
struct Box {
  Vec3 center;
  Vec3 size;
  float yawRadians = 0.0f;
};

enum class FaceDirection { Outward, Inward };

// Which of a box's faces to emit, as a bit mask (box-local axes, before the yaw).
namespace BoxFace {
inline constexpr std::uint8_t NegX = 1 << 0, PosX = 1 << 1, NegY = 1 << 2, PosY = 1 << 3, NegZ = 1 << 4,
                              PosZ = 1 << 5;
inline constexpr std::uint8_t All = NegX | PosX | NegY | PosY | NegZ | PosZ;
// For boxes standing on a floor: the bottom would be coplanar with it and never lit.
inline constexpr std::uint8_t AllButBottom = All & ~NegY;
}  // namespace BoxFace

// Number of grid cells a quad is cut into along edgeU and edgeV.
struct QuadGrid {
  int cellsU = 1;
  int cellsV = 1;
};

// One piece of a panel chart: a planar quadrilateral, corners counter-clockwise seen
// from its front, laid flat in the chart as the rectangle [s0,s1] × [t0,t1] metres
// (corner 0 at (s0,t0), 1 at (s1,t0), 2 at (s1,t1), 3 at (s0,t1)), at its true size.
// Pieces of one panel may fold (a profile strip) or leave holes (a facade around its
// openings). Corners given bit-identically in two pieces become one vertex, so a panel
// built from shared points is one connected chart without cracks.
struct PanelPiece {
  std::array<Vec3, 4> corners;
  float s0 = 0.0f, t0 = 0.0f, s1 = 0.0f, t1 = 0.0f;
  MaterialId material = 0;
};

// Triangles of one material, ready to become one glTF primitive.
struct MeshPrimitiveData {
  MaterialId material = 0;
  std::vector<float> positions;  // xyz
  std::vector<float> normals;    // xyz, unit length
  std::vector<float> texcoord0;  // uv in metres along the quad edges
  std::vector<float> texcoord1;  // lightmap uv in [0,1]²
  std::vector<std::uint32_t> indices;
};

class MeshBuilder {
 public:
  // maxEdgeLength > 0 cuts every quad into a grid whose cells are at most that
  // long in metres; 0 keeps each quad as two triangles.
  explicit MeshBuilder(float maxEdgeLength = 0.0f) : maxEdgeLength_(maxEdgeLength) {}

  void addQuad(const Quad& quad, MaterialId material);
  void addQuad(const Quad& quad, MaterialId material, QuadGrid grid);
  void addQuadWithOpening(const Quad& quad, const Opening& opening, MaterialId material);
  void addBox(const Box& box, MaterialId material, FaceDirection direction,
              std::uint8_t faces = BoxFace::All);
  // Several pieces, possibly of different materials, as one lightmap chart whose
  // extent is the pieces' bounding rectangle in (s, t) from (0, 0). Two triangles a
  // piece. Throws std::invalid_argument for a piece whose rectangle is not its size.
  void addPanel(std::vector<PanelPiece> pieces);

  size_t chartCount() const { return charts_.size() + panels_.size(); }

  // Packs the lightmap charts and emits one primitive per material, in the order
  // the materials were first used. Checks that charts are disjoint and that every
  // triangle's winding agrees with its normal (throws std::logic_error if not).
  std::vector<MeshPrimitiveData> build() const;

 private:
  struct Chart {
    Quad quad;
    MaterialId material;
    QuadGrid grid;
  };
  float maxEdgeLength_;
  std::vector<Chart> charts_;
  std::vector<std::vector<PanelPiece>> panels_;  // packed after charts_
};

}  // namespace exitance::samples
