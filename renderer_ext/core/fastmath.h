// Cheap natural log and exp for the step-size controller, which needs a factor good to a few digits,
// not libm's last bit: each ray takes a log and an exp per step, and in a curved room libm's were ~6 % of
// the render time. Both are plain arithmetic (no table, no FMA contraction: -ffp-contract=off), so they
// give the same bits on every machine and instruction set.
//
//   fast_log(x): error < 1e-8 (relative, and absolute near x = 1) for normal x > 0; callers pass
//                x >= 1e-10 (no zero, negative, subnormal, inf or NaN).
//   fast_exp(x): relative error < 1e-8 for |x| <= 700 (x is clamped to that range).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

#include "core/simd.h"

namespace wv {

WV_INLINE double fast_log(double x) {
  uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  int e = int((bits >> 52) & 0x7ff) - 1023;
  bits = (bits & 0x000fffffffffffffULL) | 0x3ff0000000000000ULL;  // mantissa m in [1, 2)
  double m;
  std::memcpy(&m, &bits, sizeof m);
  if (m > 1.4142135623730951) {  // m in [sqrt(1/2), sqrt(2))
    m *= 0.5;
    ++e;
  }
  // log m = 2 atanh(s), s = (m - 1) / (m + 1), |s| < 0.1716; the series to s^9, in Estrin form (short
  // dependency chains: a step controller waits for this value).
  const double s = (m - 1.0) / (m + 1.0), s2 = s * s, s4 = s2 * s2;
  const double p = (1.0 + s2 * (1.0 / 3)) + s4 * ((1.0 / 5 + s2 * (1.0 / 7)) + s4 * (1.0 / 9));
  return 2.0 * s * p + double(e) * 0.6931471805599453;
}

WV_INLINE double fast_exp(double x) {
  x = x < -700.0 ? -700.0 : (x > 700.0 ? 700.0 : x);  // callers never pass NaN
  const double t = x * 1.4426950408889634;
  const double n = double(int64_t(t < 0.0 ? t - 0.5 : t + 0.5));  // round half away from zero
  const double r = x - n * 0.6931471805599453;  // |r| <= 0.347
  // Taylor series to r^7 in Estrin form.
  const double r2 = r * r, r4 = r2 * r2;
  const double p = ((1.0 + r) + r2 * (1.0 / 2 + r * (1.0 / 6))) +
                   r4 * ((1.0 / 24 + r * (1.0 / 120)) + r2 * (1.0 / 720 + r * (1.0 / 5040)));
  const uint64_t bits = uint64_t(int64_t(n) + 1023) << 52;  // 2^n, n in [-1010, 1010]
  double scale;
  std::memcpy(&scale, &bits, sizeof scale);
  return p * scale;
}

}  // namespace wv
