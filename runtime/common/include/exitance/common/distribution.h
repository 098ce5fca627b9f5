// Sampling a piecewise-constant 1D distribution from its normalised CDF (n + 1 doubles, cdf[0] = 0).
// C++ passes the CDF as a pointer; GLSL names the buffer (kCdfEmitters / kCdfPunctual / the
// environment's, scene_access.glsl) and its cdf_at reads it. `cdf + k` is the CDF that starts k
// entries further in both languages (GLSL: for the environment's row CDFs, its last handle).
#ifndef EXITANCE_COMMON_DISTRIBUTION_H
#define EXITANCE_COMMON_DISTRIBUTION_H
#include "exitance/common/dialect.h"

#ifdef __cplusplus
#define CDF_TYPE const double*
#define CDF_REF const double* cdf
namespace exitance {
inline double cdf_at(const double* cdf, uint i) { return cdf[i]; }
}  // namespace exitance
#else
#define CDF_TYPE uint
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

// Probability of cell i.
EXITANCE_FN float cdf_pmf(CDF_REF, uint i) { return float(cdf_at(cdf, i + 1u) - cdf_at(cdf, i)); }

// u (which sample_cdf mapped to cell i) rescaled to [0, 1) inside the cell, in double so narrow
// cells keep their resolution; 0.5 for a cell of width 0.
EXITANCE_FN float cdf_remap(CDF_REF, uint i, float u) {
  double lo = cdf_at(cdf, i);
  double width = cdf_at(cdf, i + 1u) - lo;
  if (!(width > double(0.0f))) return 0.5f;
  return float(clamp((double(u) - lo) / width, double(0.0f), double(0.99999994f)));
}

EXITANCE_NAMESPACE_END
#endif
