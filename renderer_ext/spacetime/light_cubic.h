// The roots of Schwarzschild's light polynomial
//
//   P(u) = 1/b^2 - u^2 + 2M u^3,   u = 1/R,   (du/dphi)^2 = P,
//
// in closed form: a ray's turning point (lens_map.h) and the roots its orbit is written with
// (planar_orbit.h). With v = 2M u and beta = (2M/b)^2, v^3 - v^2 + beta = 0 has three real roots when b
// is above the critical 3 sqrt(3) M (beta < 4/27), by the trigonometric solution, and one below it, by
// Cardano's; each is then polished by Newton's method on P. Both hold to rounding for any M/b down to a
// mass too light to bend anything (the middle root is ~ 1/b there, not a difference of near-equal terms).
#pragma once

#include <algorithm>
#include <cmath>

#include "core/trig.h"

namespace wv {

struct LightCubic {
  double M, b;

  double P(double u) const { return (2.0 * M * u - 1.0) * u * u + 1.0 / (b * b); }
  double dP(double u) const { return (6.0 * M * u - 2.0) * u; }

  // Up to three Newton steps on P, each kept only where it lowers |P|.
  double polish(double u) const {
    for (int it = 0; it < 3; ++it) {
      const double d = dP(u);
      if (d == 0.0) break;
      const double n = u - P(u) / d;
      if (!(std::fabs(P(n)) < std::fabs(P(u)))) break;
      u = n;
    }
    return u;
  }

  // beta = (2M/b)^2: P has three real roots (b above critical) where beta < 4/27.
  double beta() const { return 4.0 * M * M / (b * b); }
  bool three_roots() const { return beta() < 4.0 / 27.0; }

  // theta of the trigonometric solution (three_roots()), from 1 - cos theta = 27 beta / 2 as
  // 2 asin(sqrt(27 beta / 4)) (accurate however small beta, i.e. however light the mass). Root k is
  // v = 2M u = 1/3 + (2/3) cos(theta/3 - 2 pi k/3), written without cancellation (trig_root): k = 0 the
  // largest (u3), 1 the middle one (u2, the periapsis of a ray coming in from outside the photon sphere),
  // 2 the negative one (u1).
  double theta() const { return 2.0 * std::asin(std::min(1.0, std::sqrt(6.75 * beta()))); }
  static double trig_root(double th, int k) {
    double s6, c6;
    sin_cos(th / 6.0, s6, c6);
    const double s3 = 2.0 * s6 * c6;  // sin(th / 3)
    if (k == 0) return 1.0 - (4.0 / 3.0) * s6 * s6;
    const double a = (2.0 / 3.0) * s6 * s6, c = s3 / std::sqrt(3.0);
    return k == 1 ? a + c : a - c;
  }

  // The turning point u2 of a ray from outside the photon sphere (b above critical), else NaN.
  double periapsis() const { return three_roots() ? polish(trig_root(theta(), 1) * (0.5 / M)) : NAN; }

  // The one real root (negative) where b is below critical (Cardano), polished.
  double single_root() const {
    const double q = beta() - 2.0 / 27.0, D = 0.25 * q * q - 1.0 / 729.0;  // w^3 - w/3 + q = 0, w = v - 1/3
    const double sD = std::sqrt(std::max(0.0, D));
    const double w = std::cbrt(-0.5 * q + sD) + std::cbrt(-0.5 * q - sD);
    return polish((w + 1.0 / 3.0) * (0.5 / M));
  }
};

}  // namespace wv
