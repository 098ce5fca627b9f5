#include "exitance/runtime/tangent_frames.h"

#include <cmath>

namespace exitance {
namespace {

Vec3 linear_part_times(const Matrix4d& m, Vec3 v) {
  return {float(m[0] * v.x + m[4] * v.y + m[8] * v.z), float(m[1] * v.x + m[5] * v.y + m[9] * v.z),
          float(m[2] * v.x + m[6] * v.y + m[10] * v.z)};
}

}  // namespace

TangentFrame transform_tangent_frame(const Matrix4d& m, const TangentFrame& frame, Vec3 normal_before, Vec3 normal_after) {
  TangentFrame out;
  if (!(length(frame.tangent) > 0.0f)) return out;
  const Vec3 bitangent = linear_part_times(m, cross(normal_before, frame.tangent) * frame.sign);
  out.tangent = orthonormal_to(linear_part_times(m, frame.tangent), normal_after);
  out.sign = dot(cross(normal_after, out.tangent), bitangent) < 0.0f ? -1.0f : 1.0f;
  return out;
}

std::vector<Vec3> tangent_space_normals(const std::vector<Vec3>& positions, const std::vector<Vec3>& normals,
                                        const std::vector<uint32_t>& corners) {
  std::vector<Vec3> face_sum(positions.size(), Vec3(0));
  for (size_t k = 0; k + 2 < corners.size(); k += 3) {
    const uint32_t i0 = corners[k], i1 = corners[k + 1], i2 = corners[k + 2];
    const Vec3 face = cross(positions[i1] - positions[i0], positions[i2] - positions[i0]);
    if (is_finite(face))
      for (uint32_t i : {i0, i1, i2}) face_sum[i] += face;
  }
  std::vector<Vec3> out(positions.size(), Vec3(0));
  for (size_t i = 0; i < positions.size(); ++i) {
    const Vec3 given = i < normals.size() ? normals[i] : Vec3(0);
    const float given_length = length(given);
    const Vec3 n = given_length > 1e-6f && std::isfinite(given_length) ? given : face_sum[i];
    const float len = length(n);
    if (len > 0.0f && std::isfinite(len)) out[i] = n / len;
  }
  return out;
}

std::vector<TangentFrame> generate_vertex_tangents(const std::vector<Vec3>& positions, const std::vector<Vec3>& unit_normals,
                                                   const std::vector<Vec2>& uvs, const std::vector<uint32_t>& corners) {
  const size_t n = positions.size();
  std::vector<Vec3> du(n, Vec3(0)), up(n, Vec3(0));
  for (size_t k = 0; k + 2 < corners.size(); k += 3) {
    const uint32_t i0 = corners[k], i1 = corners[k + 1], i2 = corners[k + 2];
    const Vec3 e1 = positions[i1] - positions[i0], e2 = positions[i2] - positions[i0];
    const float s1 = uvs[i1].x - uvs[i0].x, t1 = uvs[i1].y - uvs[i0].y;
    const float s2 = uvs[i2].x - uvs[i0].x, t2 = uvs[i2].y - uvs[i0].y;
    const float det = s1 * t2 - s2 * t1;
    if (!(std::fabs(det) > 0.0f)) continue;
    const Vec3 dp_du = (e1 * t2 - e2 * t1) / det;
    const Vec3 dp_dv = (e2 * s1 - e1 * s2) / det;
    if (!is_finite(dp_du) || !is_finite(dp_dv)) continue;
    for (uint32_t i : {i0, i1, i2}) du[i] += dp_du, up[i] += -dp_dv;
  }
  std::vector<TangentFrame> frames(n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3 normal = unit_normals[i];
    if (!(length(normal) > 0.0f)) continue;
    frames[i].tangent = orthonormal_to(du[i], normal);
    frames[i].sign = dot(cross(normal, frames[i].tangent), up[i]) < 0.0f ? -1.0f : 1.0f;
  }
  return frames;
}

}  // namespace exitance
