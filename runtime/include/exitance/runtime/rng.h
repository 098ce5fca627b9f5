// PCG32 (O'Neill 2014): small state, good statistics, and a stream per texel so results are
// identical whatever thread runs which texel.
#pragma once
#include <cstdint>

namespace exitance {

inline uint64_t splitmix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

class Pcg32 {
 public:
  // Independent sequence for (seed, stream, index): e.g. (user seed, texel id, sample index).
  Pcg32(uint64_t seed, uint64_t stream, uint64_t index) {
    state_ = 0;
    increment_ = (splitmix64(stream ^ splitmix64(seed)) << 1u) | 1u;
    next();
    state_ += splitmix64(seed + 0x632BE59BD9B4E019ull * (index + 1));
    next();
  }
  uint32_t next() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ull + increment_;
    uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
  }
  // Uniform in [0, 1): 24 random bits, never exactly 1.
  float uniform() { return float(next() >> 8) * (1.0f / 16777216.0f); }

 private:
  uint64_t state_;
  uint64_t increment_;
};

}  // namespace exitance
