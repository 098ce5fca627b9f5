// Sampling a piecewise-constant 1D distribution from its normalised CDF (n + 1 doubles, cdf[0] = 0).
// C++ passes the CDF as a pointer; GLSL names the buffer (kCdfEmitters / kCdfPunctual) and
// scene_access.glsl's cdf_at reads it.
#ifndef EXITANCE_COMMON_DISTRIBUTION_H
#define EXITANCE_COMMON_DISTRIBUTION_H
#include "exitance/common/dialect.h"

#ifdef __cplusplus
#define CDF_REF const double* cdf
namespace exitance {
inline double cdf_at(const double* cdf, uint i) { return cdf[i]; }
}  // namespace exitance
#else
#define CDF_REF uint cdf
#endif

EXITANCE_NAMESPACE_BEGIN

// upper_bound of u in the CDF, then back over zero-weight cells so a CDF plateau never returns
// a cell of probability 0. `pmf` receives the chosen cell's probability.
EXITANCE_FN uint sample_cdf(CDF_REF, uint n, float u, OUT(float) pmf) {
  uint lo = 0u;
  uint hi = n + 1u;  // first index with cdf > u, in [0, n + 1)
  while (lo < hi) {
    uint mid = (lo + hi) / 2u;
    if (cdf_at(cdf, mid) > double(u)) hi = mid;
    else lo = mid + 1u;
  }
  uint i = lo > 0u ? lo - 1u : 0u;
  i = min(i, n - 1u);
  while (float(cdf_at(cdf, i + 1u) - cdf_at(cdf, i)) == 0.0f && i > 0u) --i;
  pmf = float(cdf_at(cdf, i + 1u) - cdf_at(cdf, i));
  return i;
}

EXITANCE_NAMESPACE_END
#endif
