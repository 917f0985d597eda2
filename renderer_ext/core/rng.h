// Counter-based random numbers: the stream of a camera sample is a pure function of
// (seed, pixel, sample), so any tile, thread count or render order gives the same image.
#pragma once

#include <cstdint>

namespace wv {

// SplitMix64 finaliser: a bijective 64-bit mixer with full avalanche.
inline uint64_t mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// PCG32 (XSH-RR) stream seeded from the (seed, pixel, sample) counter.
class Rng {
 public:
  Rng(uint64_t seed, uint64_t pixel, uint64_t sample) {
    const uint64_t key = mix64(seed ^ mix64(pixel ^ mix64(sample + 0x632be59bd9b4e019ULL)));
    inc_ = (mix64(key + 1) << 1) | 1u;
    state_ = 0;
    next_u32();
    state_ += key;
    next_u32();
  }
  uint32_t next_u32() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    const uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    const uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32 - rot) & 31));
  }
  // Uniform in [0, 1): 53 random bits.
  double uniform() {
    const uint64_t hi = next_u32(), lo = next_u32();
    return double(((hi << 32) | lo) >> 11) * 0x1.0p-53;
  }

 private:
  uint64_t state_ = 0, inc_ = 1;
};

}  // namespace wv
