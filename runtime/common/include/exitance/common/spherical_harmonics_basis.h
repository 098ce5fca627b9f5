// Real L2 spherical harmonics (9 coefficients), Sloan's "Stupid Spherical Harmonics Tricks"
// ordering and constants: index = l*(l+1) + m, i.e. Y00, Y1-1, Y10, Y11, Y2-2, Y2-1, Y20, Y21, Y22,
// evaluated on world directions (x, y, z) as given (glTF: +Y up). probes.bin stores coefficients of
// incident radiance in this basis (DESIGN §4).
#ifndef EXITANCE_COMMON_SPHERICAL_HARMONICS_BASIS_H
#define EXITANCE_COMMON_SPHERICAL_HARMONICS_BASIS_H
#include "exitance/common/dialect.h"
EXITANCE_NAMESPACE_BEGIN

const int kShCoefficients = 9;

EXITANCE_FN void sh_basis(vec3 d, OUT_ARRAY(float, y, 9)) {
  y[0] = 0.282094792f;
  y[1] = 0.488602512f * d.y;
  y[2] = 0.488602512f * d.z;
  y[3] = 0.488602512f * d.x;
  y[4] = 1.092548431f * d.x * d.y;
  y[5] = 1.092548431f * d.y * d.z;
  y[6] = 0.315391565f * (3.0f * d.z * d.z - 1.0f);
  y[7] = 1.092548431f * d.x * d.z;
  y[8] = 0.546274215f * (d.x * d.x - d.y * d.y);
}

EXITANCE_FN int sh_band(int index) { return index == 0 ? 0 : (index < 4 ? 1 : 2); }

// Convolution with the clamped cosine divided by pi, per band: pi, 2pi/3, pi/4 over pi
// (Ramamoorthi & Hanrahan 2001). Coefficient i of E(n)/pi is this times coefficient i of L.
EXITANCE_FN float sh_cosine_lobe_over_pi(int band) { return band == 0 ? 1.0f : (band == 1 ? 2.0f / 3.0f : 0.25f); }

// Solid-angle weight of one of `count` uniform sphere samples in a Monte Carlo projection.
const float kShSphereMeasure = 12.566370614359172f;  // 4 pi

EXITANCE_NAMESPACE_END
#endif
