// PCG32 (O'Neill 2014): small state, good statistics, and an independent stream per
// (seed, stream, index) — e.g. (user seed, texel, sample) — so results do not depend on which
// thread or GPU lane runs which sample.
#ifndef EXITANCE_COMMON_RNG_H
#define EXITANCE_COMMON_RNG_H
#include "exitance/common/dialect.h"
EXITANCE_NAMESPACE_BEGIN

struct Pcg32 {
  uint64_t state;
  uint64_t increment;
};

EXITANCE_FN uint64_t splitmix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ul;
  x = (x ^ (x >> 30u)) * 0xBF58476D1CE4E5B9ul;
  x = (x ^ (x >> 27u)) * 0x94D049BB133111EBul;
  return x ^ (x >> 31u);
}

EXITANCE_FN uint pcg_next(INOUT(Pcg32) r) {
  uint64_t old = r.state;
  r.state = old * 6364136223846793005ul + r.increment;
  uint xorshifted = uint(((old >> 18u) ^ old) >> 27u);
  uint rot = uint(old >> 59u);
  return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31u));
}

EXITANCE_FN Pcg32 pcg_init(uint64_t seed, uint64_t stream, uint64_t index) {
  Pcg32 r;
  r.state = 0ul;
  r.increment = (splitmix64(stream ^ splitmix64(seed)) << 1u) | 1ul;
  pcg_next(r);
  r.state += splitmix64(seed + 0x632BE59BD9B4E019ul * (index + 1ul));
  pcg_next(r);
  return r;
}

// Uniform in [0, 1): 24 random bits, never exactly 1.
EXITANCE_FN float pcg_uniform(INOUT(Pcg32) r) { return float(pcg_next(r) >> 8u) * (1.0f / 16777216.0f); }

EXITANCE_NAMESPACE_END
#endif
