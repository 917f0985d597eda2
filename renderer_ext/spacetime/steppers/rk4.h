// Classical fixed-step Runge-Kutta 4: the seed paper's method and the baseline of every benchmark.
//
// The step is a fixed base step, halved in powers of two where the field is strong (geodesic.h picks
// the level so that h <= tol^(1/4) * r) and halved again when the conserved-quantity monitor rejects
// a step; there is no error estimate. f(ynew) is evaluated once per step and reused as the
// next step's first stage, so a step costs four right-hand sides.
#pragma once

#include "spacetime/steppers/common.h"

namespace wv {

// T is double, or Lanes for a batch of rays (ray_batch.h).
template <class M, class T = double>
struct Rk4 {
  static constexpr bool kAdaptive = false;
  static constexpr bool kAccurateDense = false;  // dense output: cubic Hermite
  static constexpr int kOrder = 4;
  static constexpr int kStages = 5, kNew = 4;  // k[0] = f(y), k[1..3] inner stages, k[4] = f(ynew)
  template <class U>
  using Rebind = Rk4<M, U>;
  T k[kStages][8];

  void init(const M& m, const T y[8]) { m.rhs(y, k[0]); }

  WV_INLINE T attempt(const M& m, const T y[8], T h, T /*tol*/, T ynew[8]) {
    T t[8];
    for (int i = 0; i < 8; ++i) t[i] = y[i] + 0.5 * h * k[0][i];
    m.rhs(t, k[1]);
    for (int i = 0; i < 8; ++i) t[i] = y[i] + 0.5 * h * k[1][i];
    m.rhs(t, k[2]);
    for (int i = 0; i < 8; ++i) t[i] = y[i] + h * k[2][i];
    m.rhs(t, k[3]);
    for (int i = 0; i < 8; ++i) ynew[i] = y[i] + h * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]) / 6.0;
    m.rhs(ynew, k[kNew]);
    return T{};
  }

  void dense(const double y[8], const double ynew[8], double h, double theta, double out[8]) const {
    hermite_dense(y, k[0], ynew, k[kNew], h, theta, out);
  }

  // Halfway through the accepted step, from its end points alone (bounds the arc; cheaper than dense).
  void midpoint(const double y[8], const double ynew[8], double h, double out[8]) const {
    hermite_midpoint(y, k[0], ynew, k[kNew], h, out);
  }

  const T* derivative_new() const { return k[kNew]; }

  void accept() {
    for (int i = 0; i < 8; ++i) k[0][i] = k[kNew][i];
  }
};

}  // namespace wv
