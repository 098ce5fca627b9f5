// The benches' relMSE weight: relMSE = mean over texels and channels of (x - r)^2 / (r^2 + 1e-3),
// the 1e-3 keeping black texels from dominating (the usual regulariser of relMSE in rendering papers).
#pragma once

inline double rel_mse_weight(double reference) { return 1.0 / (reference * reference + 1e-3); }
