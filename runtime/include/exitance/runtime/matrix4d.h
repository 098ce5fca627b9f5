// Column-major 4x4 double matrices as glTF stores them, and the two compositions the importer
// flattens node hierarchies with. Header-only and standard library only: the lighting core
// (node_transform.h) and exitance-view (which links no lighting code) place nodes with the same math.
#pragma once
#include <array>
#include <cmath>
#include <cstddef>

namespace exitance {

// 4x4 matrix, column-major as glTF stores it; double precision as the importer composes it.
using Matrix4d = std::array<double, 16>;
inline constexpr Matrix4d kIdentityMatrix4d{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

// a * b (column-major).
inline Matrix4d multiply(const Matrix4d& a, const Matrix4d& b) {
  Matrix4d r{};
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[size_t(k * 4 + row)] * b[size_t(c * 4 + k)];
      r[size_t(c * 4 + row)] = s;
    }
  return r;
}

// T * R * S with R from the quaternion (x, y, z, w) divided by its length; the caller makes sure
// the length is not zero.
inline Matrix4d trs_matrix(const std::array<double, 3>& t, const std::array<double, 4>& q,
                           const std::array<double, 3>& s) {
  const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const double qx = q[0] / len, qy = q[1] / len, qz = q[2] / len, qw = q[3] / len;
  // Column-major R*S then translation.
  const double r00 = 1 - 2 * (qy * qy + qz * qz), r01 = 2 * (qx * qy - qz * qw), r02 = 2 * (qx * qz + qy * qw);
  const double r10 = 2 * (qx * qy + qz * qw), r11 = 1 - 2 * (qx * qx + qz * qz), r12 = 2 * (qy * qz - qx * qw);
  const double r20 = 2 * (qx * qz - qy * qw), r21 = 2 * (qy * qz + qx * qw), r22 = 1 - 2 * (qx * qx + qy * qy);
  return {r00 * s[0], r10 * s[0], r20 * s[0], 0, r01 * s[1], r11 * s[1], r21 * s[1], 0,
          r02 * s[2], r12 * s[2], r22 * s[2], 0, t[0],       t[1],       t[2],       1};
}

}  // namespace exitance
