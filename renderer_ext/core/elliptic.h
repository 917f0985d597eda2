// Elliptic integrals and Jacobi elliptic functions of a real argument and parameter 0 <= m < 1, to
// double precision: Carlson's symmetric integral R_F (duplication), the complete integral K(m) (AGM), the
// incomplete F(phi | m), and sn, cn, dn from Jacobi's theta series with the nome q = exp(-pi K' / K)
// computed once per parameter (JacobiFunctions): one sine and cosine per evaluation and a few terms, since
// q < 0.45 for every m <= 0.9999 (the series' terms fall as q^(n^2): eight terms).
#pragma once

#include <algorithm>
#include <cmath>

#include "core/dual.h"
#include "core/trig.h"

namespace wv {

// Carlson's R_F(x, y, z) = 1/2 int_0^inf dt / sqrt((t + x)(t + y)(t + z)), x, y, z >= 0, at most one zero.
// Duplication until the arguments agree to 0.01 relative, then the seventh-order series (DLMF 19.36.1;
// relative error of order 0.01^8, below 1e-16: one duplication fewer than the fifth-order series needs at
// 0.0025). T is double or a Dual (core/dual.h): derivatives through the same operations.
template <class T>
T carlson_rf(T x, T y, T z) {
  for (int it = 0; it < 60; ++it) {
    // (the convergence test on the values alone: a Dual's division is three)
    const double m = (value(x) + value(y) + value(z)) / 3.0;
    const double spread = std::max(std::fabs(value(x) - m), std::max(std::fabs(value(y) - m), std::fabs(value(z) - m)));
    if (spread < 1e-2 * m) {
      const T mu = (x + y + z) / 3.0;
      const T dx = 1.0 - x / mu, dy = 1.0 - y / mu, dz = 1.0 - z / mu;
      const T e2 = dx * dy - dz * dz, e3 = dx * dy * dz;
      const T s = 1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0 - 5.0 * e2 * e2 * e2 / 208.0 +
                  3.0 * e3 * e3 / 104.0 + e2 * e2 * e3 / 16.0;
      return s / sqrt(mu);
    }
    const T sx = sqrt(x), sy = sqrt(y), sz = sqrt(z);
    const T lam = sx * (sy + sz) + sy * sz;
    x = 0.25 * (x + lam);
    y = 0.25 * (y + lam);
    z = 0.25 * (z + lam);
  }
  return T(NAN);
}

// The arithmetic-geometric mean of a and g, iterated in place until |a - g| <= tol a (at most 40 means; it
// converges quadratically however small g / a is). T is double or a Dual.
template <class T>
void agm(T& a, T& g, double tol) {
  for (int it = 0; it < 40 && std::fabs(value(a) - value(g)) > tol * value(a); ++it) {
    const T an = 0.5 * (a + g);
    g = sqrt(a * g);
    a = an;
  }
}

// R_F(0, y, z) = pi / (2 AGM(sqrt y, sqrt z)) (y, z > 0): the complete integral. T is double or a Dual.
template <class T>
T carlson_rf_complete(T y, T z) {
  T a = sqrt(y), g = sqrt(z);
  agm(a, g, 1e-15);
  return M_PI / (a + g);
}

// K(m) = F(pi/2 | m) by the arithmetic-geometric mean: pi / (2 AGM(1, sqrt(1 - m))).
inline double elliptic_k(double m) {
  double a = 1.0, g = std::sqrt(1.0 - m);
  agm(a, g, 1e-16);
  return M_PI / (2.0 * a);
}

// F(phi | m) for the amplitude phi with sin phi = s, cos phi = c (phi in [0, pi]: c may be negative),
// given K = K(m): s R_F(c^2, 1 - m s^2, 1), reflected about pi/2.
inline double elliptic_f(double s, double c, double m, double K) {
  const double f = s * carlson_rf(c * c, 1.0 - m * s * s, 1.0);
  return c >= 0.0 ? f : 2.0 * K - f;
}

struct JacobiValues {
  double sn = 0.0, cn = 1.0, dn = 1.0;
};

// sn, cn, dn(x | m) for one parameter m in (0, 0.9999]: theta series in z = pi x / (2K),
//   sn = (th3 / th2) th1(z) / th4(z),  cn = (th4 / th2) th2(z) / th4(z),  dn = (th4 / th3) th3(z) / th4(z)
// (th_i without argument: at z = 0). valid() is false above that m (the nome's series would need more
// terms than kTerms), where a caller uses another method.
class JacobiFunctions {
 public:
  static constexpr double kMaxParameter = 0.9999;

  JacobiFunctions() = default;
  explicit JacobiFunctions(double m) : m_(m) {
    if (!(m > 0.0 && m <= kMaxParameter)) return;
    // The nome q = exp(-pi K(1 - m) / K(m)): for m <= 1/2 from Jacobi's series in l = (1 - sqrt k') / (2 (1 +
    // sqrt k')), k' = sqrt(1 - m), q = l + 2 l^5 + 15 l^9 + 150 l^13 + 1707 l^17 + ... (l <= 0.043: the last
    // term below 1e-20), and then K = (pi / 2) th3^2 from the same theta constants as the functions: no
    // arithmetic-geometric mean at all (two of them, with a logarithm, were ~60 % of a closed-form orbit's
    // set-up). Above 1/2, from K and K' by their means.
    const bool series = m <= 0.5;
    double q;
    if (series) {
      // 1 - k'^(1/2) = m / ((1 + k') (1 + k'^(1/2))): no cancellation for small m.
      const double kp = std::sqrt(1.0 - m), skp = std::sqrt(kp);
      const double l = 0.5 * m / ((1.0 + kp) * (1.0 + skp) * (1.0 + skp)), l4 = (l * l) * (l * l);
      q = l * (1.0 + l4 * (2.0 + l4 * (15.0 + l4 * (150.0 + l4 * 1707.0))));
    } else {
      K_ = elliptic_k(m);
      q = std::exp(-M_PI * elliptic_k(1.0 - m) / K_);
    }
    // Coefficients: a_n = q^((n + 1/2)^2) (th1, th2), c_n = q^(n^2) (th3, th4, n >= 1).
    double th2 = 0.0, th3 = 1.0, th4 = 1.0;
    // q^(n^2) by the recurrence q^((n+1)^2) = q^(n^2) q^(2n+1); q^((n+1/2)^2) = q^(1/4) q^(n^2 + n).
    const double q4 = std::sqrt(std::sqrt(q));
    double qn2 = 1.0, q2n1 = q, qn = 1.0;  // q^(n^2), q^(2n+1), q^n
    n_ = 0;
    for (int n = 0; n < kTerms; ++n) {
      a_[n] = 2.0 * q4 * qn2 * qn;
      c_[n] = n == 0 ? 1.0 : 2.0 * qn2;
      th2 += a_[n];
      if (n > 0) {
        th3 += c_[n];
        th4 += (n % 2 ? -1.0 : 1.0) * c_[n];
      }
      n_ = n + 1;
      qn2 *= q2n1;
      q2n1 *= q * q;
      qn *= q;
      if (a_[n] < 1e-18 && (n == 0 || c_[n] < 1e-18)) break;
    }
    if (!(q < 0.5) || a_[n_ - 1] > 1e-16) return;
    if (series) K_ = 0.5 * M_PI * th3 * th3;
    s_sn_ = th3 / th2;
    s_cn_ = th4 / th2;
    s_dn_ = th4 / th3;
    scale_ = M_PI / (2.0 * K_);
    valid_ = true;
  }

  bool valid() const { return valid_; }
  double m() const { return m_; }
  double K() const { return K_; }

  JacobiValues operator()(double x) const {
    const double z = scale_ * x;
    double s1, c1;
    sin_cos(z, s1, c1);
    // sin((2n + 1) z), cos((2n + 1) z) and cos(2n z), each advanced by the recurrence
    // x_{n+1} = 2 cos(2z) x_n - x_{n-1} from its values at n = 0 and n = -1.
    const double c2 = 2.0 * c1 * c1 - 1.0, t2 = 2.0 * c2;
    double so = s1, so_prev = -s1, co = c1, co_prev = c1, ce = 1.0, ce_prev = c2;
    double th1 = a_[0] * so, th2 = a_[0] * co, th3 = 1.0, th4 = 1.0;
    for (int n = 1; n < n_; ++n) {
      const double so_n = t2 * so - so_prev, co_n = t2 * co - co_prev, ce_n = t2 * ce - ce_prev;
      so_prev = so;
      so = so_n;
      co_prev = co;
      co = co_n;
      ce_prev = ce;
      ce = ce_n;
      const double sign = n % 2 ? -1.0 : 1.0;
      th1 += sign * a_[n] * so;
      th2 += a_[n] * co;
      th3 += c_[n] * ce;
      th4 += sign * c_[n] * ce;
    }
    JacobiValues v;
    v.sn = s_sn_ * th1 / th4;
    v.cn = s_cn_ * th2 / th4;
    v.dn = s_dn_ * th3 / th4;
    return v;
  }

 private:
  static constexpr int kTerms = 10;
  double m_ = 0.0, K_ = 0.0, scale_ = 0.0, s_sn_ = 0.0, s_cn_ = 0.0, s_dn_ = 0.0;
  double a_[kTerms] = {}, c_[kTerms] = {};
  int n_ = 0;
  bool valid_ = false;
};

}  // namespace wv
