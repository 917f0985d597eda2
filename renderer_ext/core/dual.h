// Forward-mode dual numbers: a value and N partial derivatives.
//
// Metrics write their inverse metric once, templated over the scalar type; evaluating it with
// Dual<4> gives the exact coordinate derivatives of g^{mu nu} (to rounding). The contract tests use
// this to check every hand-written Hamiltonian right-hand side, and a new metric can run on the
// autodiff right-hand side alone until a hand-written one exists.
#pragma once

#include <cmath>

namespace wv {

template <int N>
struct Dual {
  double v = 0.0;
  double d[N] = {};

  Dual() = default;
  Dual(double value) : v(value) {}  // NOLINT: constants promote implicitly
  static Dual variable(double value, int k) {
    Dual r(value);
    r.d[k] = 1.0;
    return r;
  }
};

template <int N>
inline Dual<N> operator+(const Dual<N>& a, const Dual<N>& b) {
  Dual<N> r(a.v + b.v);
  for (int k = 0; k < N; ++k) r.d[k] = a.d[k] + b.d[k];
  return r;
}
template <int N>
inline Dual<N> operator-(const Dual<N>& a, const Dual<N>& b) {
  Dual<N> r(a.v - b.v);
  for (int k = 0; k < N; ++k) r.d[k] = a.d[k] - b.d[k];
  return r;
}
template <int N>
inline Dual<N> operator-(const Dual<N>& a) {
  Dual<N> r(-a.v);
  for (int k = 0; k < N; ++k) r.d[k] = -a.d[k];
  return r;
}
template <int N>
inline Dual<N> operator*(const Dual<N>& a, const Dual<N>& b) {
  Dual<N> r(a.v * b.v);
  for (int k = 0; k < N; ++k) r.d[k] = a.d[k] * b.v + a.v * b.d[k];
  return r;
}
template <int N>
inline Dual<N> operator/(const Dual<N>& a, const Dual<N>& b) {
  const double inv = 1.0 / b.v;
  Dual<N> r(a.v * inv);
  for (int k = 0; k < N; ++k) r.d[k] = (a.d[k] - r.v * b.d[k]) * inv;
  return r;
}
template <int N>
inline Dual<N> operator+(const Dual<N>& a, double b) { return a + Dual<N>(b); }
template <int N>
inline Dual<N> operator+(double a, const Dual<N>& b) { return Dual<N>(a) + b; }
template <int N>
inline Dual<N> operator-(const Dual<N>& a, double b) { return a - Dual<N>(b); }
template <int N>
inline Dual<N> operator-(double a, const Dual<N>& b) { return Dual<N>(a) - b; }
template <int N>
inline Dual<N> operator*(const Dual<N>& a, double b) { return a * Dual<N>(b); }
template <int N>
inline Dual<N> operator*(double a, const Dual<N>& b) { return Dual<N>(a) * b; }
template <int N>
inline Dual<N> operator/(const Dual<N>& a, double b) { return a / Dual<N>(b); }
template <int N>
inline Dual<N> operator/(double a, const Dual<N>& b) { return Dual<N>(a) / b; }

template <int N>
inline Dual<N> sqrt(const Dual<N>& a) {
  const double s = std::sqrt(a.v);
  Dual<N> r(s);
  const double f = 0.5 / s;
  for (int k = 0; k < N; ++k) r.d[k] = a.d[k] * f;
  return r;
}

template <int N>
inline bool operator<(const Dual<N>& a, double b) { return a.v < b; }
template <int N>
inline bool operator>(const Dual<N>& a, double b) { return a.v > b; }

// Scalar-generic code inside namespace wv calls sqrt(T) for both doubles and duals.
inline double sqrt(double x) { return std::sqrt(x); }

inline double value(double x) { return x; }
template <int N>
inline double value(const Dual<N>& x) { return x.v; }

}  // namespace wv
