// Stratified pixel positions: the first two dimensions of the Sobol sequence (a (0, 2)-sequence: any
// 2^k consecutive points from the start put one point in each of 2^k equal boxes of every shape), Owen-
// scrambled per pixel by a hashed nested uniform permutation (the Laine-Karras / Burley construction,
// written here from the papers' description), so the points of different pixels are independent while
// each pixel's samples stay stratified for every sample count. A pixel's n-th point depends only on
// (seed, pixel, n), like everything else a sample draws (core/rng.h).
#pragma once

#include <cstdint>

#include "core/rng.h"

namespace wv {

namespace detail {

inline uint32_t reverse_bits(uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  return (x >> 16) | (x << 16);
}

// A permutation of 32-bit integers in which each bit depends only on the bits below it (applied to
// bit-reversed values it is a nested uniform scramble of [0, 1) in base 2).
inline uint32_t laine_karras(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

inline uint32_t owen(uint32_t v, uint32_t seed) { return reverse_bits(laine_karras(reverse_bits(v), seed)); }

// Sobol dimension 1 (dimension 0 is the bit-reversed index): direction numbers v_{k+1} = v_k ^ (v_k >> 1).
inline uint32_t sobol1(uint32_t i) {
  uint32_t r = 0, v = 0x80000000u;
  for (; i; i >>= 1, v ^= v >> 1)
    if (i & 1u) r ^= v;
  return r;
}

inline uint64_t pixel_key(uint64_t seed, uint64_t pixel) { return mix64(seed ^ mix64(pixel + 0x9e3779b97f4a7c15ULL)); }

// Point i of the scrambled (0, 2)-sequence with the two coordinates' scrambles keyed by `key`.
inline void scrambled_point(uint32_t i, uint64_t key, double& x, double& y) {
  const uint32_t a = owen(reverse_bits(i), uint32_t(key));
  const uint32_t b = owen(sobol1(i), uint32_t(key >> 32));
  x = (double(a) + 0.5) * 0x1.0p-32;
  y = (double(b) + 0.5) * 0x1.0p-32;
}
}  // namespace detail

// The sample-th stratified point of pixel `pixel` in [0, 1)^2.
inline void pixel_sample(uint64_t seed, uint64_t pixel, uint64_t sample, double& x, double& y) {
  detail::scrambled_point(uint32_t(sample), detail::pixel_key(seed, pixel), x, y);
}

// The sample-th point of the pixel's stratified pair of dimensions number `dim` (>= 1; pixel_sample's camera point
// is pair 0) in [0, 1)^2: the same scrambled (0, 2)-sequence, scrambled apart for each pair, its index shuffled by
// a nested uniform scramble of its own (Burley, "Practical Hash-based Owen Scrambling", 2020: "padding"). The
// shuffle keeps every aligned block of 2^k indices together (bit j of the shuffled index is bit j of the index
// flipped by a function of the bits above it), so the first 2^k samples of a pair are still a (0, k, 2)-net, while
// the pairs of one sample are decorrelated: unshuffled, every pair's first coordinate would take its top bit from
// the index's lowest bit, and the pairs would be coupled along a diagonal.
inline void padded_sample(uint64_t seed, uint64_t pixel, uint64_t dim, uint64_t sample, double& x, double& y) {
  const uint64_t key = mix64(detail::pixel_key(seed, pixel) ^ mix64(dim + 0xd1b54a32d192ed03ULL));
  const uint32_t i = detail::owen(uint32_t(sample), uint32_t(mix64(key)));
  detail::scrambled_point(i, key, x, y);
}

}  // namespace wv
