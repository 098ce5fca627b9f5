// Small vector helpers every integrator and kernel uses.
#ifndef EXITANCE_COMMON_VECTOR_FUNCTIONS_H
#define EXITANCE_COMMON_VECTOR_FUNCTIONS_H
#include "exitance/common/dialect.h"
EXITANCE_NAMESPACE_BEGIN

EXITANCE_FN float max_component(vec3 a) { return max(a.x, max(a.y, a.z)); }

// Rec. 709 luminance of linear RGB.
EXITANCE_FN float luminance(vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

// Orthonormal basis around a unit normal (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
// The sign is that of n.z including -0 (std::copysign), read from the bits so both languages agree.
EXITANCE_FN void orthonormal_basis(vec3 n, OUT(vec3) t, OUT(vec3) b) {
  float sign_z = (floatBitsToUint(n.z) & 0x80000000u) != 0u ? -1.0f : 1.0f;
  float a = -1.0f / (sign_z + n.z);
  float bb = n.x * n.y * a;
  t = vec3(1.0f + sign_z * n.x * n.x * a, sign_z * bb, -sign_z * n.x);
  b = vec3(bb, sign_z + n.y * n.y * a, -n.y);
}

EXITANCE_NAMESPACE_END
#endif
