// GLSL twin of runtime/include/exitance/runtime/rng.h: PCG32 with one stream per (seed, texel, sample).

uint64_t splitmix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ul;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ul;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBul;
  return x ^ (x >> 31);
}

struct Pcg32 { uint64_t state; uint64_t increment; };

uint pcg_next(inout Pcg32 r) {
  uint64_t old = r.state;
  r.state = old * 6364136223846793005ul + r.increment;
  uint xorshifted = uint(((old >> 18u) ^ old) >> 27u);
  uint rot = uint(old >> 59u);
  return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31u));
}

Pcg32 pcg_init(uint64_t seed, uint64_t stream, uint64_t index) {
  Pcg32 r;
  r.state = 0ul;
  r.increment = (splitmix64(stream ^ splitmix64(seed)) << 1u) | 1ul;
  pcg_next(r);
  r.state += splitmix64(seed + 0x632BE59BD9B4E019ul * (index + 1ul));
  pcg_next(r);
  return r;
}

// Uniform in [0, 1): 24 random bits.
float pcg_uniform(inout Pcg32 r) { return float(pcg_next(r) >> 8) * (1.0 / 16777216.0); }
