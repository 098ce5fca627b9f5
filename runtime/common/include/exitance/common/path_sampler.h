// The random numbers of a path (texel or probe sample): one stream per (seed, item, sample index),
// each draw a new dimension, so the same (seed, item, sample) gives the same path on every backend
// and thread.
//
// kSamplerSobol (default): Owen-scrambled Sobol points, shuffled per dimension (Burley 2020,
// "Practical Hash-based Owen Scrambling", JCGT 9(4)). A 2-D draw (sample_2d) takes the first two
// Sobol dimensions at a per-dimension shuffled index, so an item's first 2^k samples of that draw are
// stratified in every 2^-k-area elementary interval; a 1-D draw is a scrambled van der Corput point at
// a shuffled index.
// Different items and dimensions get independent hashed scrambles, so each point is uniform on its own
// (the estimator stays unbiased) while an item's samples are stratified against each other.
// kSamplerIndependent: independent uniform numbers (a hash of item, sample and dimension), the
// baseline the low-discrepancy sampler is measured against.
#ifndef EXITANCE_COMMON_PATH_SAMPLER_H
#define EXITANCE_COMMON_PATH_SAMPLER_H
#include "exitance/common/dialect.h"
#include "exitance/common/rng.h"
EXITANCE_NAMESPACE_BEGIN

const uint kSamplerSobol = 0u;
const uint kSamplerIndependent = 1u;

struct PathSampler {
  uint item_hash;  // of (seed, stream): scrambles differ per texel/probe
  uint index;      // the sample number within the item
  uint dimension;  // draws so far
  uint mode;       // kSampler*
};

// A 32-bit integer hash with good avalanche (Wellons' "lowbias32").
EXITANCE_FN uint hash_u32(uint x) {
  x ^= x >> 16u;
  x *= 0x7feb352du;
  x ^= x >> 15u;
  x *= 0x846ca68bu;
  x ^= x >> 16u;
  return x;
}

// Laine-Karras permutation with Burley's constants: output bit k depends only on input bits <= k.
EXITANCE_FN uint laine_karras_permutation(uint x, uint seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

// Owen scrambling of a 0.32 fixed-point number: each bit flipped by a hash of the bits above it.
EXITANCE_FN uint nested_uniform_scramble(uint x, uint seed) {
  return bitfieldReverse(laine_karras_permutation(bitfieldReverse(x), seed));
}

// Bit i of the result is the XOR of the bits of x whose positions are supersets of i (as bit
// masks): a superset-sum (zeta) transform over GF(2) in five butterfly steps.
EXITANCE_FN uint superset_parity(uint x) {
  x ^= (x >> 1u) & 0x55555555u;
  x ^= (x >> 2u) & 0x33333333u;
  x ^= (x >> 4u) & 0x0F0F0F0Fu;
  x ^= (x >> 8u) & 0x00FF00FFu;
  x ^= (x >> 16u) & 0x0000FFFFu;
  return x;
}

// The second Sobol dimension of `index` as 0.32 fixed point (the first is bitfieldReverse(index)).
// Its direction numbers are Pascal's triangle mod 2: digit i (from the top) is the XOR of the index
// bits k with C(k, i) odd, i.e. (Lucas) with k a superset of i. So no loop over the index's bits
// (which, for a shuffled index, are all 32 and cost a sixth of a CPU bake).
EXITANCE_FN uint sobol_second_dimension(uint index) { return bitfieldReverse(superset_parity(index)); }

// An Owen-scrambled 0.32 fixed-point number given by its digits in bit-reversed order:
// nested_uniform_scramble(bitfieldReverse(reversed_digits), seed) with two reversals cancelled. The
// Sobol dimensions come this way: the first's reversed digits are the index itself, the second's are
// superset_parity(index).
EXITANCE_FN uint scrambled_from_reversed_digits(uint reversed_digits, uint seed) {
  return bitfieldReverse(laine_karras_permutation(reversed_digits, seed));
}

EXITANCE_FN float fixed_point_to_unit(uint x) { return float(x >> 8u) * (1.0f / 16777216.0f); }

EXITANCE_FN PathSampler path_sampler(uint64_t seed, uint64_t stream, uint sample_index, uint mode) {
  PathSampler s;
  s.item_hash = uint(splitmix64(stream ^ splitmix64(seed)) >> 32u);
  s.index = sample_index;
  s.dimension = 0u;
  s.mode = mode;
  return s;
}

// This draw's scramble seed; advances the dimension.
EXITANCE_FN uint next_dimension_seed(INOUT(PathSampler) s) {
  uint seed = hash_u32(s.item_hash ^ hash_u32(s.dimension * 0x9E3779B9u + 0x632BE5ABu));
  s.dimension += 1u;
  return seed;
}

// Uniform in [0, 1), never exactly 1.
EXITANCE_FN float sample_1d(INOUT(PathSampler) s) {
  uint seed = next_dimension_seed(s);
  if (s.mode == kSamplerIndependent) return fixed_point_to_unit(hash_u32(seed ^ hash_u32(s.index)));
  // Owen-scrambled van der Corput (Sobol's first dimension) at a shuffled index. The shuffle is what
  // keeps two dimensions independent: scrambled copies of one sequence at the same index share its
  // digits up to a flip (the first bit of every dimension would be index & 1, flipped or not).
  uint shuffled = nested_uniform_scramble(s.index, seed);
  return fixed_point_to_unit(scrambled_from_reversed_digits(shuffled, hash_u32(seed ^ 0x68E31DA4u)));
}

// Uniform on [0, 1)^2; one dimension of the stream.
EXITANCE_FN vec2 sample_2d(INOUT(PathSampler) s) {
  uint seed = next_dimension_seed(s);
  if (s.mode == kSamplerIndependent) {
    uint h = hash_u32(seed ^ hash_u32(s.index));
    return vec2(fixed_point_to_unit(h), fixed_point_to_unit(hash_u32(h ^ 0x85EBCA6Bu)));
  }
  uint shuffled = nested_uniform_scramble(s.index, seed);
  uint x = scrambled_from_reversed_digits(shuffled, hash_u32(seed ^ 0x68E31DA4u));
  uint y = scrambled_from_reversed_digits(superset_parity(shuffled), hash_u32(seed ^ 0xB5297A4Du));
  return vec2(fixed_point_to_unit(x), fixed_point_to_unit(y));
}

EXITANCE_NAMESPACE_END
#endif
