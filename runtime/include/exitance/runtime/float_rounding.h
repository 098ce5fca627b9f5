// A double rounded to the nearest float at or below (above) it: the float bounds that hold a value
// computed in double (the spatial-split builder's fragment boxes, the BVH refit's carried
// fragments, the octree's origin and size).
#pragma once
#include <cmath>

namespace exitance {

inline float float_at_or_below(double v) {
  const float f = float(v);
  return double(f) > v ? std::nextafter(f, -INFINITY) : f;
}

inline float float_at_or_above(double v) {
  const float f = float(v);
  return double(f) < v ? std::nextafter(f, INFINITY) : f;
}

}  // namespace exitance
