// Kerr's critical impact parameter by inclination: the edge of its shadow, from its spherical photon orbits.
//
// A spherical photon orbit of radius r between the prograde and the retrograde equatorial circular one has
// (Bardeen 1973; M the mass, a the spin length, E = 1)
//   xi(r)  = L_z = -(r^3 - 3 M r^2 + a^2 r + a^2 M) / (a (r - M)),
//   eta(r) = Q   = r^3 (4 a^2 M - r (r - 3 M)^2) / (a^2 (r - M)^2).
// A far ray that approaches it, seen at polar angle theta from the spin axis, has impact parameter
// b = sqrt(eta + xi^2 + a^2 cos^2 theta) (the radius on the observer's sky: alpha^2 + beta^2, alpha = -xi / sin theta,
// beta^2 = eta + a^2 cos^2 theta - xi^2 cot^2 theta), and its angular momentum is inclined to the spin by cos i =
// xi / b, which falls from 1 (prograde, on the equator) to -1 (retrograde) along the orbits. Rays of that
// inclination with a smaller b fall in.
#pragma once

#include <algorithm>
#include <cmath>

namespace wv {

// The equatorial circular photon orbit of Kerr (mass M, spin length a), prograde (sense -1) or retrograde (+1)
// (Bardeen, Press & Teukolsky 1972).
inline double kerr_photon_orbit(double M, double a, double sense) {
  return 2.0 * M * (1.0 + std::cos(2.0 / 3.0 * std::acos(std::clamp(sense * std::fabs(a) / M, -1.0, 1.0))));
}

// The critical impact parameter of light whose angular momentum makes cosine c (in [-1, 1]) with the spin, seen at
// cos theta = cos_theta (0: in the equatorial plane): 3 sqrt(3) M without spin; on the equator
// 6 M cos(acos(-+|a| / M) / 3) -+ |a| (c = +-1); over the poles (c = 0, cos_theta = 1) sqrt(eta + a^2).
inline double kerr_critical_impact(double M, double a, double c, double cos_theta = 0.0) {
  const double s = std::fabs(a);
  if (!(s > 1e-9 * M)) return std::sqrt(27.0) * M;
  c = std::clamp(c, -1.0, 1.0);
  auto at = [&](double r, double& b) {
    const double xi = -(r * r * r - 3.0 * M * r * r + s * s * r + s * s * M) / (s * (r - M));
    const double k = r - 3.0 * M;
    const double eta = std::max(0.0, r * r * r * (4.0 * s * s * M - r * k * k) / (s * s * (r - M) * (r - M)));
    b = std::sqrt(eta + xi * xi + s * s * cos_theta * cos_theta);
    return xi / b;
  };
  double lo = kerr_photon_orbit(M, s, -1.0), hi = kerr_photon_orbit(M, s, 1.0), b = 0.0;
  for (int it = 0; it < 100 && hi - lo > 1e-15 * hi; ++it) {
    const double r = 0.5 * (lo + hi);
    (at(r, b) > c ? lo : hi) = r;
  }
  at(0.5 * (lo + hi), b);
  return b;
}

// The Schwarzschild mass whose critical impact parameter, sqrt(27) M, is Kerr's for cosine c on the equator: the
// Kerr proposal's proxy mass for that inclination before its blend (integrators/lens_proposal.h, ProxyMass).
inline double kerr_critical_mass(double M, double a, double c) {
  return kerr_critical_impact(M, a, c) / std::sqrt(27.0);
}

}  // namespace wv
