// Tangent frames for normal maps (glTF normalTexture): the importer's TANGENT import and generation,
// scene edits' moves, and exitance-view's evaluation of a normal map share these.
//
// Convention (glTF): the tangent t points along increasing u of the normal map's UV set, and the
// bitangent b = w * cross(n, t) along decreasing v, which is "up" in the image since glTF's UV
// origin is the image's top-left corner (a normal map's +Y is up). Generated tangents are the
// per-vertex sum of the triangles' dp/du (Lengyel's method), not MikkTSpace: where a glTF has no
// TANGENT attribute, the frames (so the mapped normals) can differ from an engine that runs
// MikkTSpace, most along UV seams and on strongly curved meshes.
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

#include "exitance/runtime/matrix4d.h"
#include "exitance/runtime/vec_math.h"

namespace exitance {

struct TangentFrame {
  Vec3 tangent{0, 0, 0};  // unit, or zero: no frame (a normal map is not applied there)
  float sign = 1.0f;      // handedness w, +1 or -1
};

// A frame moved by the linear part of m: the tangent as a surface direction (renormalized), the
// sign such that sign * cross(normal_after, tangent) points along m times the old bitangent
// sign * cross(normal_before, tangent) (a mirroring m flips it). normal_after is the surface's
// normal after the move (the importer's and the edits' normal rule). A zero tangent stays zero.
TangentFrame transform_tangent_frame(const Matrix4d& m, const TangentFrame& frame, Vec3 normal_before, Vec3 normal_after);

// The per-vertex unit normals a mesh's frames are built against: `normals[i]` normalized where it
// is finite and not (nearly) zero, else the normalized sum of the face normals of the triangles
// (`corners`: 3 vertex indices each) at vertex i, zero for a vertex on none.
std::vector<Vec3> tangent_space_normals(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                                        const std::vector<uint32_t>& corners);

// Per-vertex frames from UV derivatives: `corners` lists 3 vertex indices per triangle, `unit_normals`
// come from tangent_space_normals. Each triangle adds its dp/du and -dp/dv
// (unnormalized: larger triangles weigh more) to its three vertices; then t is dp/du made
// orthogonal to n and normalized, w the sign of dot(cross(n, t), -dp/dv). Triangles whose UVs are
// degenerate add nothing; a vertex left without a tangent gets a zero one.
std::vector<TangentFrame> generate_vertex_tangents(const std::vector<Vec3>& positions, const std::vector<Vec3>& unit_normals,
                                                   const std::vector<Vec2>& uvs, const std::vector<uint32_t>& corners);

// The normal-mapped shading normal: tangent-space m = (2 rgb - 1) * (scale, scale, 1) from the
// normal texture's linear texel, put into the frame (t made orthogonal to the unit normal n,
// b = w * cross(n, t)) and normalized. Returns n unchanged where the frame is zero or degenerate
// or the mapped normal is zero. Header-only: exitance-view links no runtime library.
inline Vec3 orthonormal_to(Vec3 v, Vec3 n) {  // v without its part along unit n, normalized (or zero)
  const Vec3 t = v - n * dot(n, v);
  const float len = length(t);
  return len > 1e-12f && std::isfinite(len) ? t / len : Vec3(0);
}

inline Vec3 perturbed_normal(Vec3 n, const TangentFrame& frame, Vec3 texel_rgb, float scale) {
  const Vec3 t = orthonormal_to(frame.tangent, n);
  if (!(length(t) > 0.0f)) return n;
  const Vec3 b = cross(n, t) * frame.sign;
  const Vec3 m{(2.0f * texel_rgb.x - 1.0f) * scale, (2.0f * texel_rgb.y - 1.0f) * scale, 2.0f * texel_rgb.z - 1.0f};
  const Vec3 mapped = t * m.x + b * m.y + n * m.z;
  const float len = length(mapped);
  return len > 1e-12f && std::isfinite(len) ? mapped / len : n;
}

}  // namespace exitance
