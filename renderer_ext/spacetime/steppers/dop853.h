// Dormand-Prince 8(5,3): the high-accuracy reference stepper, with Hairer's combined 5th/3rd-order
// error estimate. Twelve right-hand sides per accepted step (the 13th, f(ynew), is reused). Dense
// output is the cubic Hermite interpolant of the step, enough to locate horizon and escape crossings.
#pragma once

#include "spacetime/steppers/common.h"
#include "spacetime/steppers/dop853_tableau.h"

namespace wv {

// T is double, or Lanes for a batch of rays (ray_batch.h).
template <class M, class T = double>
struct Dop853 {
  static constexpr bool kAdaptive = true;
  static constexpr bool kAccurateDense = false;  // dense output: cubic Hermite: far less accurate than the step
  static constexpr int kOrder = 8;  // controller exponent 1/8
  static constexpr int S = dop853::kStages;
  static constexpr int kStages = S + 1, kNew = S;  // k[0] = f(y), k[S] = f(ynew)
  template <class U>
  using Rebind = Dop853<M, U>;
  T k[kStages][8];

  void init(const M& m, const T y[8]) { m.rhs(y, k[0]); }

  WV_INLINE T attempt(const M& m, const T y[8], T h, T tol, T ynew[8]) {
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

  void dense(const double y[8], const double ynew[8], double h, double theta, double out[8]) const {
    hermite_dense(y, k[0], ynew, k[S], h, theta, out);
  }

  // Halfway through the accepted step, from its end points alone (bounds the arc; cheaper than dense).
  void midpoint(const double y[8], const double ynew[8], double h, double out[8]) const {
    hermite_midpoint(y, k[0], ynew, k[S], h, out);
  }

  const T* derivative_new() const { return k[S]; }

  void accept() {
    for (int i = 0; i < 8; ++i) k[0][i] = k[S][i];
  }
};

}  // namespace wv
