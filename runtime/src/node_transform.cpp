#include "exitance/runtime/node_transform.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace exitance {

Matrix4d local_matrix(const SceneNode& node) {
  return node.has_matrix ? node.matrix : trs_matrix(node.translation, node.rotation, node.scale);
}

std::vector<std::optional<Matrix4d>> node_world_matrices(const Scene& scene) {
  const size_t n = scene.nodes.size();
  std::vector<std::optional<Matrix4d>> world(n);
  std::vector<int> chain;
  for (size_t i = 0; i < n; ++i) {
    if (!scene.nodes[i].in_scene || world[i]) continue;
    // Walk up to the first node whose world is known (or a root), then down again.
    chain.clear();
    for (int at = int(i); at >= 0 && !world[size_t(at)]; at = scene.nodes[size_t(at)].parent) {
      if (size_t(at) >= n) throw std::invalid_argument("node " + std::to_string(i) + ": parent " + std::to_string(at) + " does not exist");
      if (chain.size() > n) throw std::invalid_argument("node " + std::to_string(i) + " is its own ancestor");
      chain.push_back(at);
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const int parent = scene.nodes[size_t(*it)].parent;
      const Matrix4d& parent_world = parent >= 0 && world[size_t(parent)] ? *world[size_t(parent)] : kIdentityMatrix4d;
      world[size_t(*it)] = multiply(parent_world, local_matrix(scene.nodes[size_t(*it)]));
    }
  }
  return world;
}

Vec3 transform_point(const Matrix4d& m, Vec3 p) {
  return {float(m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12]), float(m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13]),
          float(m[2] * p.x + m[6] * p.y + m[10] * p.z + m[14])};
}

Vec3 transform_normal(const Matrix4d& m, Vec3 n) {
  const double a = m[0], b = m[4], c = m[8], d = m[1], e = m[5], f = m[9], g = m[2], h = m[6], i = m[10];
  const double c00 = e * i - f * h, c01 = -(d * i - f * g), c02 = d * h - e * g;
  const double c10 = -(b * i - c * h), c11 = a * i - c * g, c12 = -(a * h - b * g);
  const double c20 = b * f - c * e, c21 = -(a * f - c * d), c22 = a * e - b * d;
  // Cofactor c_rc times n (row r of the result is row r of the cofactor matrix dotted with n).
  return {float(c00 * n.x + c01 * n.y + c02 * n.z), float(c10 * n.x + c11 * n.y + c12 * n.z),
          float(c20 * n.x + c21 * n.y + c22 * n.z)};
}

double determinant3(const Matrix4d& m) {
  return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) + m[8] * (m[1] * m[6] - m[5] * m[2]);
}

std::optional<Matrix4d> affine_inverse(const Matrix4d& m) {
  const double det = determinant3(m);
  if (!(std::fabs(det) > 0) || !std::isfinite(det)) return std::nullopt;
  // Inverse of the 3x3 part: the transposed cofactor matrix over det.
  const double a = m[0], b = m[4], c = m[8], d = m[1], e = m[5], f = m[9], g = m[2], h = m[6], i = m[10];
  Matrix4d r{};
  r[0] = (e * i - f * h) / det, r[4] = -(b * i - c * h) / det, r[8] = (b * f - c * e) / det;
  r[1] = -(d * i - f * g) / det, r[5] = (a * i - c * g) / det, r[9] = -(a * f - c * d) / det;
  r[2] = (d * h - e * g) / det, r[6] = -(a * h - b * g) / det, r[10] = (a * e - b * d) / det;
  for (int row = 0; row < 3; ++row)
    r[size_t(12 + row)] = -(r[size_t(row)] * m[12] + r[size_t(4 + row)] * m[13] + r[size_t(8 + row)] * m[14]);
  r[15] = 1;
  for (double v : r)
    if (!std::isfinite(v)) return std::nullopt;
  return r;
}

bool place_light(const Matrix4d& world, PunctualLight& light) {
  const Vec3 position = transform_point(world, {0, 0, 0});
  const Vec3 forward = transform_point(world, {0, 0, -1}) - position;
  if (!(length(forward) > 0.0f)) return false;
  light.position = position;
  light.direction = normalize(forward);
  return true;
}

}  // namespace exitance
