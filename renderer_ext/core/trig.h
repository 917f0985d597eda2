// Sine and cosine of one argument together, to within ~1 ulp (absolute error <= 2.3e-16 against libm over
// |x| <= 20), about twice as fast as libm's sincos for the closed-form orbits, which evaluate two of them per
// point (the theta series' argument and the azimuth): the argument is reduced by pi/2 in three parts
// (Cody-Waite: k P1 and k P2 are exact for |k| < 2^20), and sine and cosine of the remainder |r| <= pi/4 are
// their Taylor polynomials to r^15 and r^16 (the next terms are below 5e-17 there). Plain arithmetic, so the
// same bits on every machine and instruction set; |x| >= 1e5 and non-finite x go to libm.
#pragma once

#include <cmath>
#include <cstdint>

namespace wv {

inline void sin_cos(double x, double& s, double& c) {
  if (!(std::fabs(x) < 1e5)) {
    s = std::sin(x);
    c = std::cos(x);
    return;
  }
  constexpr double kTwoOverPi = 0.63661977236758134308;
  constexpr double kP1 = 1.5707963267341256, kP2 = 6.077100506303966e-11, kP3 = 2.0222662487959506e-21;
  const double k = std::nearbyint(x * kTwoOverPi);
  const double r = ((x - k * kP1) - k * kP2) - k * kP3, r2 = r * r;
  const double sr =
      r + r * r2 *
              (-1.0 / 6.0 +
               r2 * (1.0 / 120.0 +
                     r2 * (-1.0 / 5040.0 +
                           r2 * (1.0 / 362880.0 +
                                 r2 * (-1.0 / 39916800.0 + r2 * (1.0 / 6227020800.0 + r2 * (-1.0 / 1307674368000.0)))))));
  const double cr =
      1.0 - 0.5 * r2 +
      r2 * r2 *
          (1.0 / 24.0 +
           r2 * (-1.0 / 720.0 +
                 r2 * (1.0 / 40320.0 +
                       r2 * (-1.0 / 3628800.0 +
                             r2 * (1.0 / 479001600.0 + r2 * (-1.0 / 87178291200.0 + r2 * (1.0 / 20922789888000.0)))))));
  switch (int64_t(k) & 3) {
    case 0: s = sr; c = cr; break;
    case 1: s = cr; c = -sr; break;
    case 2: s = -sr; c = -cr; break;
    default: s = -cr; c = sr; break;
  }
}

}  // namespace wv
