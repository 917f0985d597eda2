// Shared pieces of the steppers: the error norm, cubic Hermite dense output, stepper identifiers.
//
// Every stepper has the same small interface, used by integrate_ray (geodesic.h):
//   void init(const M&, const double y[8])      derivative at the start of the next step
//   double attempt(const M&, y, h, tol, ynew)    one trial step; returns the scaled error norm
//                                                (<= 1 accept; 0 for fixed-step methods)
//   void accept()                                the trial step was accepted: reuse f(ynew)
//   void dense(y, ynew, h, theta, out)           state at y + theta*h within the accepted step
//   const double* derivative_new()               f(ynew) of the last trial step (for free H checks)
//   void midpoint(y, ynew, h, out)               cheap estimate of the state halfway through the
//                                                step (cubic Hermite), for bounding its arc
//   static constexpr bool kAdaptive; static constexpr int kOrder;
//   static constexpr bool kAccurateDense;        dense output about as accurate as a step (the continuous
//                                                extensions of dopri5 and dop853), not cubic Hermite (rk4)
//
// The steppers are templated over the value type T (double, or Lanes for a batch of rays, one per lane;
// ray_batch.h). Their whole state is `T k[kStages][8]`: k[0] = f(y) at the start of the step, k[kNew] =
// f(ynew) after an attempt; `Rebind<U>` is the same stepper over value type U.
#pragma once

#include <cmath>

#include "core/simd.h"

namespace wv {

enum class StepperKind : int { kRk4 = 0, kDopri5 = 1, kDop853 = 2 };

// RMS of err_i / (tol + tol * max(|y_i|, |ynew_i|)) over the state, except coordinate time t (index 0),
// which feeds back into nothing and would otherwise limit steps on long rays. T is double or Lanes.
template <class T>
WV_INLINE T error_norm(const T err[8], const T y[8], const T ynew[8], T tol) {
  T s = T{};
  for (int i = 1; i < 8; ++i) {
    const T sc = tol * (1.0 + max_of(abs_of(y[i]), abs_of(ynew[i])));
    const T e = err[i] / sc;
    s += e * e;
  }
  return sqrt(s / 7.0);
}

// Cubic Hermite interpolant between (y0, f0) and (y1, f1) over a step of length h.
inline void hermite_dense(const double y0[8], const double f0[8], const double y1[8], const double f1[8], double h,
                          double theta, double out[8]) {
  const double t2 = theta * theta, t3 = t2 * theta;
  const double h00 = 2 * t3 - 3 * t2 + 1, h10 = t3 - 2 * t2 + theta, h01 = -2 * t3 + 3 * t2, h11 = t3 - t2;
  for (int i = 0; i < 8; ++i) out[i] = h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i];
}

// Halfway point of the cubic Hermite interpolant: (y0 + y1) / 2 + h (f0 - f1) / 8.
inline void hermite_midpoint(const double y0[8], const double f0[8], const double y1[8], const double f1[8], double h,
                             double out[8]) {
  for (int i = 0; i < 8; ++i) out[i] = 0.5 * (y0[i] + y1[i]) + 0.125 * h * (f0[i] - f1[i]);
}

}  // namespace wv
