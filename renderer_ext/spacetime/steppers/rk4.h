// Classical fixed-step Runge-Kutta 4: the seed paper's method and the baseline of every benchmark.
//
// The step is a fixed base step, halved in powers of two where the field is strong (geodesic.h picks
// the level so that h <= tol^(1/4) * r) and halved again when the conserved-quantity monitor rejects
// a step; there is no error estimate. f(ynew) is evaluated once per step and reused as the
// next step's first stage, so a step costs four right-hand sides.
#pragma once

#include "spacetime/steppers/common.h"

namespace wv {

template <class M>
struct Rk4 {
  static constexpr bool kAdaptive = false;
  static constexpr int kOrder = 4;
  double k1[8], k2[8], k3[8], k4[8], fnew[8];

  void init(const M& m, const double y[8]) { m.rhs(y, k1); }

  double attempt(const M& m, const double y[8], double h, double /*tol*/, double ynew[8]) {
    double t[8];
    for (int i = 0; i < 8; ++i) t[i] = y[i] + 0.5 * h * k1[i];
    m.rhs(t, k2);
    for (int i = 0; i < 8; ++i) t[i] = y[i] + 0.5 * h * k2[i];
    m.rhs(t, k3);
    for (int i = 0; i < 8; ++i) t[i] = y[i] + h * k3[i];
    m.rhs(t, k4);
    for (int i = 0; i < 8; ++i) ynew[i] = y[i] + h * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]) / 6.0;
    m.rhs(ynew, fnew);
    return 0.0;
  }

  void dense(const double y[8], const double ynew[8], double h, double theta, double out[8]) const {
    hermite_dense(y, k1, ynew, fnew, h, theta, out);
  }

  const double* derivative_new() const { return fnew; }

  void accept() {
    for (int i = 0; i < 8; ++i) k1[i] = fnew[i];
  }
};

}  // namespace wv
