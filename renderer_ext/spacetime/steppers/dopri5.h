// Dormand-Prince 5(4) with FSAL and its 4th-order continuous extension (Hairer, Norsett & Wanner,
// Solving ODEs I, II.5-II.6). The default stepper: six right-hand sides per accepted step.
#pragma once

#include "spacetime/steppers/common.h"

namespace wv {

// T is double, or Lanes for a batch of rays (one ray per lane, each with its own step h).
template <class M, class T = double>
struct Dopri5 {
  static constexpr bool kAdaptive = true;
  static constexpr bool kAccurateDense = true;  // dense output: its continuous extension is as accurate as the step
  static constexpr int kOrder = 5;  // error estimate of order 4: controller exponent 1/5
  static constexpr int kStages = 7, kNew = 6;  // k[0] = f(y); k[6] = f(ynew) after attempt (FSAL)
  template <class U>
  using Rebind = Dopri5<M, U>;
  T k[kStages][8];

  void init(const M& m, const T y[8]) { m.rhs(y, k[0]); }

  WV_INLINE T attempt(const M& m, const T y[8], T h, T tol, T ynew[8]) {
    constexpr double a21 = 1.0 / 5;
    constexpr double a31 = 3.0 / 40, a32 = 9.0 / 40;
    constexpr double a41 = 44.0 / 45, a42 = -56.0 / 15, a43 = 32.0 / 9;
    constexpr double a51 = 19372.0 / 6561, a52 = -25360.0 / 2187, a53 = 64448.0 / 6561, a54 = -212.0 / 729;
    constexpr double a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247, a64 = 49.0 / 176,
                     a65 = -5103.0 / 18656;
    constexpr double b1 = 35.0 / 384, b3 = 500.0 / 1113, b4 = 125.0 / 192, b5 = -2187.0 / 6784, b6 = 11.0 / 84;
    constexpr double e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920, e5 = -17253.0 / 339200,
                     e6 = 22.0 / 525, e7 = -1.0 / 40;
    T t[8];
    for (int i = 0; i < 8; ++i) t[i] = y[i] + h * a21 * k[0][i];
    m.rhs(t, k[1]);
    for (int i = 0; i < 8; ++i) t[i] = y[i] + h * (a31 * k[0][i] + a32 * k[1][i]);
    m.rhs(t, k[2]);
    for (int i = 0; i < 8; ++i) t[i] = y[i] + h * (a41 * k[0][i] + a42 * k[1][i] + a43 * k[2][i]);
    m.rhs(t, k[3]);
    for (int i = 0; i < 8; ++i) t[i] = y[i] + h * (a51 * k[0][i] + a52 * k[1][i] + a53 * k[2][i] + a54 * k[3][i]);
    m.rhs(t, k[4]);
    for (int i = 0; i < 8; ++i)
      t[i] = y[i] + h * (a61 * k[0][i] + a62 * k[1][i] + a63 * k[2][i] + a64 * k[3][i] + a65 * k[4][i]);
    m.rhs(t, k[5]);
    for (int i = 0; i < 8; ++i)
      ynew[i] = y[i] + h * (b1 * k[0][i] + b3 * k[2][i] + b4 * k[3][i] + b5 * k[4][i] + b6 * k[5][i]);
    m.rhs(ynew, k[6]);
    T err[8];
    for (int i = 0; i < 8; ++i)
      err[i] = h * (e1 * k[0][i] + e3 * k[2][i] + e4 * k[3][i] + e5 * k[4][i] + e6 * k[5][i] + e7 * k[6][i]);
    return error_norm(err, y, ynew, tol);
  }

  // 4th-order continuous extension of the accepted step (Hairer's dense-output coefficients).
  void dense(const double y[8], const double ynew[8], double h, double theta, double out[8]) const {
    constexpr double d1 = -12715105075.0 / 11282082432, d3 = 87487479700.0 / 32700410799,
                     d4 = -10690763975.0 / 1880347072, d5 = 701980252875.0 / 199316789632,
                     d6 = -1453857185.0 / 822651844, d7 = 69997945.0 / 29380423;
    const double th1 = 1.0 - theta;
    for (int i = 0; i < 8; ++i) {
      const double r2 = ynew[i] - y[i];
      const double r3 = h * k[0][i] - r2;
      const double r4 = r2 - h * k[6][i] - r3;
      const double r5 = h * (d1 * k[0][i] + d3 * k[2][i] + d4 * k[3][i] + d5 * k[4][i] + d6 * k[5][i] + d7 * k[6][i]);
      out[i] = y[i] + theta * (r2 + th1 * (r3 + theta * (r4 + th1 * r5)));
    }
  }

  // Halfway through the accepted step, from its end points alone (bounds the arc; cheaper than dense).
  void midpoint(const double y[8], const double ynew[8], double h, double out[8]) const {
    hermite_midpoint(y, k[0], ynew, k[6], h, out);
  }

  const T* derivative_new() const { return k[kNew]; }

  void accept() {
    for (int i = 0; i < 8; ++i) k[0][i] = k[6][i];
  }
};

}  // namespace wv
