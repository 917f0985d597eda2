// The orbit of a light ray in closed form, for the static spherical metrics whose lens polynomial
// (lens_map.h) is the cubic of Schwarzschild,
//
//   (du/dphi)^2 = P(u) = 1/b^2 - u^2 + 2M u^3,   u = 1/R,
//
// so u(phi) is a Jacobi elliptic function of the swept azimuth (Chandrasekhar, The Mathematical Theory of
// Black Holes, section 20). With the roots of P:
//
// * b above the critical 3 sqrt(3) M (roots u1 < 0 < u2 < u3), the ray outside the photon sphere:
//     u = u1 + (u2 - u1) sn^2(psi | m),  m = (u2 - u1) / (u3 - u1),  dpsi/dphi = sqrt(M (u3 - u1) / 2),
//   u increasing (inward) for psi in (0, K), the periapsis u2 at psi = K, outward to u = 0 before 2K;
// * b below it (one real root u1 < 0, complex pair with |u1 - root|^2 = A^2 = P'(u1) / 2M):
//     u = u1 + A (1 - cn psi) / (1 + cn psi),  m = (A + mu - u1) / (2A),  |dpsi/dphi| = sqrt(2 M A),
//   mu the pair's real part, u growing with psi from u1 (psi = 0) to infinity (psi = 2K): the ray falls in
//   if it moves inward and escapes to u = 0 if outward.
//
// phi_of(u) is the inverse on a branch, by Carlson's R_F. Rays that start inside the photon sphere with b
// above critical, rays within ~1e-8 of the critical b (m > 0.9999) and near-radial ones are left to the
// integrator (valid() false).
#pragma once

#include <algorithm>
#include <cmath>

#include "core/elliptic.h"
#include "spacetime/lens_map.h"
#include "spacetime/light_cubic.h"

namespace wv {

class PlanarOrbit {
 public:
  PlanarOrbit() = default;

  // The orbit through u0 = 1/R0 with impact parameter b, moving inward (u increasing) or outward.
  PlanarOrbit(double M, double b, double u0, bool inward) : M_(M), b_(b), inward_(inward) {
    if (!(M > 0.0 && b > 0.0 && u0 > 0.0) || b * u0 < 1e-6) return;
    const LightCubic cubic{M, b};
    const double inv2M = 0.5 / M;
    if (cubic.three_roots()) {
      three_ = true;
      const double th = cubic.theta();
      u1_ = cubic.polish(LightCubic::trig_root(th, 2) * inv2M);
      u2_ = cubic.polish(LightCubic::trig_root(th, 1) * inv2M);
      u3_ = inv2M - u1_ - u2_;
      if (!(u1_ < 0.0 && u2_ > 0.0 && u3_ > u2_)) return;
      if (u0 > u2_ * (1.0 + 1e-12)) return;  // inside the photon sphere: not this branch
      m_ = (u2_ - u1_) / (u3_ - u1_);
      gamma_ = std::sqrt(0.5 * M * (u3_ - u1_));
      jac_ = JacobiFunctions(m_);
      if (!jac_.valid()) return;
      K_ = jac_.K();
      const double psi_in = branch_in(std::min(u0, u2_));
      psi0_ = inward ? psi_in : 2.0 * K_ - psi_in;
      dir_ = 1.0;
    } else {
      u1_ = cubic.single_root();
      if (!(u1_ < 0.0)) return;
      const double A2 = cubic.dP(u1_) / (2.0 * M);
      if (!(A2 > 0.0)) return;
      A_ = std::sqrt(A2);
      const double mu = 0.5 * (inv2M - u1_);  // real part of the complex pair (the roots sum to 1 / 2M)
      m_ = (A_ + mu - u1_) / (2.0 * A_);
      gamma_ = std::sqrt(2.0 * M * A_);
      jac_ = JacobiFunctions(m_);
      if (!jac_.valid()) return;
      K_ = jac_.K();
      psi0_ = branch_in(u0);
      dir_ = inward ? 1.0 : -1.0;
    }
    valid_ = std::isfinite(psi0_) && std::isfinite(gamma_);
  }

  bool valid() const { return valid_; }
  // Whether the ray reaches a periapsis ahead or moves inward until it falls in (b below critical).
  bool falls_in() const { return !three_ && inward_; }

  // The largest u the orbit reaches ahead of a start at u0, unless it falls in: the periapsis, or the start
  // itself for a ray below the critical impact parameter moving outward.
  double u_peak(double u0) const { return three_ ? u2_ : u0; }

  // A bound on the curvature of the orbit drawn in the plane (kappa = 3M u^5 / (1/b^2 + 2M u^3)^(3/2),
  // which grows with u) where u <= u_max, or anywhere up to the periapsis (through_periapsis).
  double curvature_bound(double u_max, bool through_periapsis) const {
    const double u = through_periapsis && three_ ? std::max(u_max, u2_) : u_max;
    const double u2 = u * u;
    return 3.0 * M_ * u2 * u2 * u * b_ * b_ * b_;
  }

  // u and du/dphi at azimuth phi (0 at the start).
  double u(double phi, double* dudphi = nullptr) const {
    const double psi = psi0_ + dir_ * gamma_ * phi;
    const JacobiValues j = jac_(psi);
    if (three_) {
      if (dudphi) *dudphi = gamma_ * 2.0 * (u2_ - u1_) * j.sn * j.cn * j.dn;
      return u1_ + (u2_ - u1_) * j.sn * j.sn;
    }
    const double den = 1.0 / (1.0 + j.cn);
    if (dudphi) *dudphi = dir_ * gamma_ * 2.0 * A_ * j.sn * j.dn * den * den;
    return u1_ + A_ * (1.0 - j.cn) * den;
  }

  // d^2u/dphi^2 at u (the orbit equation, whatever the branch).
  double ddu(double u) const { return 3.0 * M_ * u * u - u; }
  // d^3u/dphi^3 at u with du/dphi = du.
  double dddu(double u, double du) const { return (6.0 * M_ * u - 1.0) * du; }

  // The azimuth at which the ray is at u on its inward (u increasing) or outward branch; NaN where that
  // branch does not reach u or reached it behind the start.
  double phi_of(double u, bool outward) const {
    if (!valid_ || !(u >= 0.0)) return NAN;
    double psi;
    if (three_) {
      if (u > u2_) return NAN;
      const double in = branch_in(u);
      psi = outward ? 2.0 * K_ - in : in;
    } else {
      if (outward == inward_) return NAN;
      psi = branch_in(u);
    }
    const double phi = dir_ * (psi - psi0_) / gamma_;
    return phi >= -1e-12 ? std::max(0.0, phi) : NAN;
  }

 private:
  // psi on the branch where u grows with psi from its start: in [0, K] (three roots) or [0, 2K).
  double branch_in(double u) const {
    if (three_) {
      const double s2 = std::max(0.0, std::min(1.0, (u - u1_) / (u2_ - u1_)));
      return elliptic_f(std::sqrt(s2), std::sqrt(1.0 - s2), m_, K_);
    }
    const double e = u - u1_;
    const double c = (A_ - e) / (A_ + e);  // cn psi
    const double s = 2.0 * std::sqrt(A_ * e) / (A_ + e);
    return elliptic_f(s, c, m_, K_);
  }

  double M_ = 0.0, b_ = 0.0;
  bool inward_ = true, three_ = false, valid_ = false;
  double u1_ = 0.0, u2_ = 0.0, u3_ = 0.0, A_ = 0.0;
  double m_ = 0.0, K_ = 0.0, gamma_ = 0.0, psi0_ = 0.0, dir_ = 1.0;
  JacobiFunctions jac_;
};

}  // namespace wv
