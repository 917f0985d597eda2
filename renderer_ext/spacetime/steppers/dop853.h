// Dormand-Prince 8(5,3): the high-accuracy reference stepper, with Hairer's combined 5th/3rd-order
// error estimate. Twelve right-hand sides per accepted step (the 13th, f(ynew), is reused). Dense
// output is the cubic Hermite interpolant of the step, enough to locate horizon and escape crossings.
#pragma once

#include "spacetime/steppers/common.h"
#include "spacetime/steppers/dop853_tableau.h"

namespace wv {

template <class M>
struct Dop853 {
  static constexpr bool kAdaptive = true;
  static constexpr int kOrder = 8;  // controller exponent 1/8
  static constexpr int S = dop853::kStages;
  double k[S + 1][8];  // k[0] = f(y), k[S] = f(ynew)

  void init(const M& m, const double y[8]) { m.rhs(y, k[0]); }

  double attempt(const M& m, const double y[8], double h, double tol, double ynew[8]) {
    double t[8];
    for (int s = 1; s < S; ++s) {
      for (int i = 0; i < 8; ++i) {
        double acc = 0.0;
        for (int j = 0; j < s; ++j) acc += dop853::A[s][j] * k[j][i];
        t[i] = y[i] + h * acc;
      }
      m.rhs(t, k[s]);
    }
    for (int i = 0; i < 8; ++i) {
      double acc = 0.0;
      for (int j = 0; j < S; ++j) acc += dop853::B[j] * k[j][i];
      ynew[i] = y[i] + h * acc;
    }
    m.rhs(ynew, k[S]);
    double e5n = 0.0, e3n = 0.0;
    for (int i = 1; i < 8; ++i) {
      double a5 = 0.0, a3 = 0.0;
      for (int j = 0; j <= S; ++j) {
        a5 += dop853::E5[j] * k[j][i];
        a3 += dop853::E3[j] * k[j][i];
      }
      const double sc = tol * (1.0 + std::fmax(std::fabs(y[i]), std::fabs(ynew[i])));
      e5n += (a5 / sc) * (a5 / sc);
      e3n += (a3 / sc) * (a3 / sc);
    }
    if (e5n == 0.0 && e3n == 0.0) return 0.0;
    return std::fabs(h) * e5n / std::sqrt((e5n + 0.01 * e3n) * 7.0);
  }

  void dense(const double y[8], const double ynew[8], double h, double theta, double out[8]) const {
    hermite_dense(y, k[0], ynew, k[S], h, theta, out);
  }

  const double* derivative_new() const { return k[S]; }

  void accept() {
    for (int i = 0; i < 8; ++i) k[0][i] = k[S][i];
  }
};

}  // namespace wv
