// The elementary functions of a line element's expressions (warpviz/spacetime/line_element/codegen.py) for
// every value type a metric is templated over: double, Dual<N> (exact derivatives by the chain rule) and
// Lanes (lane by lane, each lane the double function, so a ray's bits do not depend on its lane).
// sqrt is in core/dual.h and core/simd.h; abs_of in core/simd.h.
#pragma once

#include <cmath>

#include "core/dual.h"
#include "core/simd.h"

namespace wv {

#define WV_ELEMENTARY(NAME, STDF, DERIV)                                              \
  inline double NAME(double x) { return STDF(x); }                                    \
  template <int N>                                                                    \
  inline Dual<N> NAME(const Dual<N>& a) {                                             \
    const double x = a.v;                                                             \
    const double d = (DERIV);                                                         \
    Dual<N> r(STDF(x));                                                               \
    for (int k = 0; k < N; ++k) r.d[k] = d * a.d[k];                                  \
    return r;                                                                         \
  }                                                                                   \
  WV_INLINE Lanes NAME(Lanes v) {                                                     \
    Lanes r;                                                                          \
    for (int i = 0; i < kLanes; ++i) r[i] = STDF(v[i]);                               \
    return r;                                                                         \
  }

WV_ELEMENTARY(exp_of, std::exp, std::exp(x))
WV_ELEMENTARY(log_of, std::log, 1.0 / x)
WV_ELEMENTARY(sin_of, std::sin, std::cos(x))
WV_ELEMENTARY(cos_of, std::cos, -std::sin(x))
WV_ELEMENTARY(tan_of, std::tan, 1.0 / (std::cos(x) * std::cos(x)))
WV_ELEMENTARY(sinh_of, std::sinh, std::cosh(x))
WV_ELEMENTARY(cosh_of, std::cosh, std::sinh(x))
WV_ELEMENTARY(tanh_of, std::tanh, 1.0 / (std::cosh(x) * std::cosh(x)))
WV_ELEMENTARY(asin_of, std::asin, 1.0 / std::sqrt(1.0 - x * x))
WV_ELEMENTARY(acos_of, std::acos, -1.0 / std::sqrt(1.0 - x * x))
WV_ELEMENTARY(atan_of, std::atan, 1.0 / (1.0 + x * x))
WV_ELEMENTARY(fabs_of, std::fabs, (x < 0.0 ? -1.0 : 1.0))

#undef WV_ELEMENTARY

// sign(x) = -1, 0, +1 (the derivative of |x|), derivative 0.
inline double sign_of(double x) { return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0); }
template <int N>
inline Dual<N> sign_of(const Dual<N>& a) {
  return Dual<N>(sign_of(a.v));
}
WV_INLINE Lanes sign_of(Lanes v) {
  Lanes r;
  for (int i = 0; i < kLanes; ++i) r[i] = sign_of(v[i]);
  return r;
}

inline double atan2_of(double y, double x) { return std::atan2(y, x); }
template <int N>
inline Dual<N> atan2_of(const Dual<N>& y, const Dual<N>& x) {
  const double q = x.v * x.v + y.v * y.v;
  Dual<N> r(std::atan2(y.v, x.v));
  for (int k = 0; k < N; ++k) r.d[k] = (x.v * y.d[k] - y.v * x.d[k]) / q;
  return r;
}
WV_INLINE Lanes atan2_of(Lanes y, Lanes x) {
  Lanes r;
  for (int i = 0; i < kLanes; ++i) r[i] = std::atan2(y[i], x[i]);
  return r;
}

}  // namespace wv
