// Where an escaped ray goes at infinity: the momentum change still to come beyond its last state, as a
// first-order Born tail along the straight continuation (a Gauss-Legendre rule), so the integration can stop
// at a finite radius (GeodesicRay's tail radius, geodesic.h).
#pragma once

#include <cmath>

namespace wv {

// Gauss-Legendre rule on [0, 1], nodes by Newton iteration on the Legendre recurrence.
template <int N>
struct GaussLegendre {
  double x[N], w[N];
  GaussLegendre() {
    for (int i = 0; i < N; ++i) {
      double z = std::cos(M_PI * (i + 0.75) / (N + 0.5)), dp = 1.0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1.0, p1 = z;
        for (int k = 2; k <= N; ++k) {
          const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = N * (z * p1 - p0) / (z * z - 1.0);
        const double dz = p1 / dp;
        z -= dz;
        if (std::fabs(dz) < 1e-16) break;
      }
      x[i] = 0.5 * (1.0 - z);
      w[i] = 1.0 / ((1.0 - z * z) * dp * dp);
    }
  }
};

inline const GaussLegendre<16>& gauss_legendre16() {
  static const GaussLegendre<16> rule;
  return rule;
}

// Direction of motion at infinity of an outgoing ray at state y. The momentum change still to come is
// integrated along the straight continuation x + v s (first-order Born approximation, 16-point
// Gauss-Legendre in u = c / (c + s)), so the error is second order in the field left beyond y:
// O(M^2 b / r^3) for a mass M, instead of the O(M b / r^2) of taking the local direction.
template <class M>
void asymptotic_direction(const M& m, const double y[8], double dir[3]) {
  double f[8];
  m.rhs(y, f);
  const double v[3] = {f[1], f[2], f[3]};
  const double vn = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  const double r0 = std::sqrt(y[1] * y[1] + y[2] * y[2] + y[3] * y[3]);
  double p[3] = {y[5], y[6], y[7]};
  if (vn > 0.0 && r0 > 0.0) {
    const double c = r0 / vn;
    const auto& gl = gauss_legendre16();
    double ys[8], fs[8];
    for (int q = 0; q < 16; ++q) {
      const double u = gl.x[q], s = c * (1.0 - u) / u, w = gl.w[q] * c / (u * u);
      for (int i = 0; i < 8; ++i) ys[i] = y[i];
      for (int i = 0; i < 3; ++i) ys[1 + i] += v[i] * s;
      m.rhs(ys, fs);
      for (int i = 0; i < 3; ++i) p[i] += w * fs[5 + i];
    }
  }
  const double pn = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
  for (int i = 0; i < 3; ++i) dir[i] = pn > 0.0 ? p[i] / pn : 0.0;
}

}  // namespace wv
