// Dormand-Prince 8(5,3): the high-accuracy reference stepper, with Hairer's combined 5th/3rd-order
// error estimate. Twelve right-hand sides per accepted step (the 13th, f(ynew), is reused). Dense
// output is Hairer's 7th-order interpolant (Solving ODEs I, II.6): three more right-hand sides, taken
// only for a step whose dense output is asked for (a surface, horizon or escape crossing near it),
// then shared by every evaluation within that step.
#pragma once

#include "spacetime/steppers/common.h"
#include "spacetime/steppers/dop853_tableau.h"

namespace wv {

// T is double, or Lanes for a batch of rays (ray_batch.h).
template <class M, class T = double>
struct Dop853 {
  static constexpr bool kAdaptive = true;
  static constexpr bool kAccurateDense = true;  // dense output: 7th order, like the step
  static constexpr int kOrder = 8;  // controller exponent 1/8
  static constexpr int S = dop853::kStages;
  static constexpr int kStages = S + 1, kNew = S;  // k[0] = f(y), k[S] = f(ynew)
  template <class U>
  using Rebind = Dop853<M, U>;
  T k[kStages][8];
  // Dense output of the last trial step (scalar steppers only): the metric for its extra stages, and
  // its interpolant's coefficients once computed.
  const M* metric = nullptr;
  mutable bool dense_ready = false;
  mutable double q[7][8];

  void init(const M& m, const T y[8]) {
    m.rhs(y, k[0]);
    dense_ready = false;
  }

  WV_INLINE T attempt(const M& m, const T y[8], T h, T tol, T ynew[8]) {
    metric = &m;
    dense_ready = false;
    T t[8];
    for (int s = 1; s < S; ++s) {
      for (int i = 0; i < 8; ++i) {
        T acc = T{};
        for (int j = 0; j < s; ++j) acc += dop853::A[s][j] * k[j][i];
        t[i] = y[i] + h * acc;
      }
      m.rhs(t, k[s]);
    }
    for (int i = 0; i < 8; ++i) {
      T acc = T{};
      for (int j = 0; j < S; ++j) acc += dop853::B[j] * k[j][i];
      ynew[i] = y[i] + h * acc;
    }
    m.rhs(ynew, k[S]);
    T e5n = T{}, e3n = T{};
    for (int i = 1; i < 8; ++i) {
      T a5 = T{}, a3 = T{};
      for (int j = 0; j <= S; ++j) {
        a5 += dop853::E5[j] * k[j][i];
        a3 += dop853::E3[j] * k[j][i];
      }
      const T sc = tol * (1.0 + max_of(abs_of(y[i]), abs_of(ynew[i])));
      e5n += (a5 / sc) * (a5 / sc);
      e3n += (a3 / sc) * (a3 / sc);
    }
    // Hairer's combined estimate; 0 where both estimates vanish.
    const T den = sqrt((e5n + 0.01 * e3n) * 7.0);
    const T e = abs_of(h) * e5n / den;
    return den == 0.0 ? T{} : e;
  }

  // State at y + theta h within the last trial step (y -> ynew, step h):
  // y + theta (q0 + (1 - theta) (q1 + theta (q2 + (1 - theta) (q3 + theta (q4 + (1 - theta) (q5 + theta q6)))))).
  void dense(const double y[8], const double ynew[8], double h, double theta, double out[8]) const {
    if (!dense_ready) prepare_dense(y, ynew, h);
    const double th1 = 1.0 - theta;
    for (int i = 0; i < 8; ++i) {
      double v = q[6][i] * theta;
      v = (v + q[5][i]) * th1;
      v = (v + q[4][i]) * theta;
      v = (v + q[3][i]) * th1;
      v = (v + q[2][i]) * theta;
      v = (v + q[1][i]) * th1;
      out[i] = y[i] + (v + q[0][i]) * theta;
    }
  }

  // The three extra stages and the interpolant's coefficients.
  void prepare_dense(const double y[8], const double ynew[8], double h) const {
    using namespace dop853;
    double kx[kExtra][8], t[8];
    auto stage = [&](int j, int i) { return j <= S ? k[j][i] : kx[j - S - 1][i]; };
    for (int e = 0; e < kExtra; ++e) {
      const int s = S + 1 + e;
      for (int i = 0; i < 8; ++i) {
        double acc = 0.0;
        for (int j = 0; j < s; ++j) acc += AX[e][j] * stage(j, i);
        t[i] = y[i] + h * acc;
      }
      metric->rhs(t, kx[e]);
    }
    for (int i = 0; i < 8; ++i) {
      const double dy = ynew[i] - y[i];
      q[0][i] = dy;
      q[1][i] = h * k[0][i] - dy;
      q[2][i] = 2.0 * dy - h * (k[S][i] + k[0][i]);
      for (int r = 0; r < 4; ++r) {
        double acc = 0.0;
        for (int j = 0; j < kExtended; ++j) acc += D[r][j] * stage(j, i);
        q[3 + r][i] = h * acc;
      }
    }
    dense_ready = true;
  }

  // Halfway through the accepted step, from its end points alone (bounds the arc; cheaper than dense).
  void midpoint(const double y[8], const double ynew[8], double h, double out[8]) const {
    hermite_midpoint(y, k[0], ynew, k[S], h, out);
  }

  const T* derivative_new() const { return k[S]; }

  void accept() {
    for (int i = 0; i < 8; ++i) k[0][i] = k[S][i];
    dense_ready = false;
  }
};

}  // namespace wv
