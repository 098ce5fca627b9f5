// What the bundle lookups return (bundle.h). Plain values: RGB as three floats, SH as 9 RGB
// coefficients in Sloan's order (index l*(l+1)+m), so the API exposes no vector-math types.
#pragma once
#include <array>
#include <cstdint>

namespace exitance::loader {

using Rgb = std::array<float, 3>;
using Point3 = std::array<float, 3>;
using ShRgbCoefficients = std::array<Rgb, 9>;  // incident radiance L(w), coefficient i, channel c at [i][c]

struct ProbeShResult {
  ShRgbCoefficients sh{};  // all zero when !usable
  bool usable = false;     // false: no usable probe in the grid cell around the point
};

struct ProbeIrradianceResult {
  Rgb irradiance_over_pi{0, 0, 0};  // E(n)/pi; zero when !usable
  bool usable = false;
};

struct SvoExitanceResult {
  Rgb exitance{0, 0, 0};    // radiant exitance M = pi * L_o of the node side facing the normal
  bool found = false;       // false: the point is outside the octree's cube (or the octree is empty)
  uint32_t level = 0;       // level of the node actually reached (<= the requested level)
  uint32_t node = 0;        // its index in SparseVoxelOctree::nodes
  bool back_side = false;   // true when the back side faced the normal
};

}  // namespace exitance::loader
