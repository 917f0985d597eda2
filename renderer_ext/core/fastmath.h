// Cheap natural log and exp for the step-size controller, which needs a factor good to a few digits,
// not libm's last bit: each ray takes a log and two exps per step attempt, and in a curved room libm's
// were ~6 % of the render time. Both are plain arithmetic (no table, no FMA contraction:
// -ffp-contract=off) over T = double or Lanes (core/simd.h) with the same operations, so they give the
// same bits on every machine, instruction set, and lane: a batch computes them for all its rays at once.
//
//   fast_log(x): error < 1e-8 (relative, and absolute near x = 1) for normal x > 0; callers pass
//                x >= 1e-10 (no zero, negative, subnormal, inf or NaN).
//   fast_exp(x): relative error < 1e-8 for |x| <= 700 (x is clamped to that range; no NaN).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/simd.h"

namespace wv {

typedef int64_t LanesI64 __attribute__((vector_size(8 * kLanes)));

// Bit casts and integer <-> double conversions for doubles and lanes alike.
WV_INLINE int64_t bits_of(double x) {
  int64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}
WV_INLINE LanesI64 bits_of(Lanes x) { return (LanesI64)x; }
WV_INLINE double from_bits(int64_t b) {
  double x;
  std::memcpy(&x, &b, sizeof x);
  return x;
}
WV_INLINE Lanes from_bits(LanesI64 b) { return (Lanes)b; }
WV_INLINE double to_double(int64_t i) { return double(i); }
WV_INLINE Lanes to_double(LanesI64 i) { return __builtin_convertvector(i, Lanes); }
WV_INLINE int64_t trunc_to_int(double x) { return int64_t(x); }
WV_INLINE LanesI64 trunc_to_int(Lanes x) { return __builtin_convertvector(x, LanesI64); }

template <class T>
WV_INLINE T fast_log(T x) {
  auto bits = bits_of(x);
  auto e = ((bits >> 52) & 0x7ff) - 1023;
  bits = (bits & 0x000fffffffffffffLL) | 0x3ff0000000000000LL;  // mantissa m in [1, 2)
  T m = from_bits(bits);
  const auto big = m > 1.4142135623730951;  // m in [sqrt(1/2), sqrt(2)):
  m = big ? m * 0.5 : m;
  e = big ? e + 1 : e;
  // log m = 2 atanh(s), s = (m - 1) / (m + 1), |s| < 0.1716; the series to s^9, in Estrin form (short
  // dependency chains: a step controller waits for this value).
  const T s = (m - 1.0) / (m + 1.0), s2 = s * s, s4 = s2 * s2;
  const T p = (1.0 + s2 * (1.0 / 3)) + s4 * ((1.0 / 5 + s2 * (1.0 / 7)) + s4 * (1.0 / 9));
  return 2.0 * s * p + to_double(e) * 0.6931471805599453;
}

template <class T>
WV_INLINE T fast_exp(T x) {
  x = x < -700.0 ? T{} - 700.0 : x;
  x = x > 700.0 ? T{} + 700.0 : x;
  const T t = x * 1.4426950408889634;
  const auto n = trunc_to_int(t < 0.0 ? t - 0.5 : t + 0.5);  // round half away from zero
  const T r = x - to_double(n) * 0.6931471805599453;  // |r| <= 0.347
  // Taylor series to r^7 in Estrin form.
  const T r2 = r * r, r4 = r2 * r2;
  const T p = ((1.0 + r) + r2 * (1.0 / 2 + r * (1.0 / 6))) +
              r4 * ((1.0 / 24 + r * (1.0 / 120)) + r2 * (1.0 / 720 + r * (1.0 / 5040)));
  return p * from_bits((n + 1023) << 52);  // 2^n, n in [-1010, 1010]
}

}  // namespace wv
