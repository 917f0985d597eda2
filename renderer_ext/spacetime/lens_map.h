// The exact lens map of a static, spherically symmetric spacetime, for connecting two points by light.
//
// A metric that is static and spherically symmetric can be written in its areal radius R as
//
//   ds^2 = -A(R) dt^2 + dR^2 / (A(R) h(R)) + R^2 dOmega^2,
//
// with A (the lapse squared) and h polynomials in u = 1 / R (Schwarzschild: A = 1 - 2Mu, h = 1;
// Reissner-Nordstrom: A = 1 - 2Mu + Q^2 u^2; Ellis: A = 1, h = 1 - b0^2 u^2, zero at the throat). A light
// ray with impact parameter b = L / E stays in the plane through its start and the centre and sweeps
//
//   dphi = b du / sqrt(P(u)),   P(u) = h(u) (1 - b^2 u^2 A(u)),
//
// so the rays from point A to point B (radii R_A, R_B, angle gamma = AOB) are the roots of Phi = gamma +
// 2 pi n (the short way, n windings) or 2 pi - gamma + 2 pi n (the long way), Phi the azimuth a ray swept
// on its way from R_A to R_B (Perlick's exact lens equation). The image of order m has Phi in
// [m pi, (m + 1) pi). On each of this file's branch parameters tau, Phi grows monotonically from 0 (the
// radial ray) to infinity (rays that approach the photon sphere or the throat), so every order has exactly
// one image and each is a bracketed 1-D root.
//
// Where P is Schwarzschild's cubic, P = 2M b^2 (u - u1)(u2 - u)(u3 - u) with the turning point u2, the
// azimuth between two radii is Carlson's R_F of the roots (B. C. Carlson, Math. Comp. 51 (1988) 267:
// int_y^x du / sqrt(prod (a_i + b_i u)) = 2 R_F(U12^2, U13^2, U23^2)), exact to rounding at any b.
// Otherwise the integrals are evaluated in t, u = u_t - t^2 around the turning point u_t (periapsis, or the throat a
// ray passes through to the other sheet), where P(u_t - t^2) = t^2 D(t^2) with D a polynomial from the
// Taylor shift of P: no cancellation, no singular endpoint, Gauss-Legendre converges geometrically; rays
// that nearly graze the photon sphere get graded pieces towards t = 0. Relative error of Phi: below 1e-11
// for rays whose b exceeds the critical one by more than 1e-6 relative (the order-0 to order-2 images of
// scenes outside ~1.05 photon-sphere radii), ~2e-8 within 1e-10 of it.
//
// Derivatives come by forward-mode AD (core/dual.h) through the root of P and the quadrature, so each
// image comes with dPhi/dpsi, psi its emission angle from the outward radial direction in the static
// observer's frame (sin psi = b u sqrt(A)), which gives the lens map's area Jacobian.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/dual.h"
#include "core/elliptic.h"
#include "core/trig.h"
#include "spacetime/light_cubic.h"

namespace wv {

// What a static spherical metric declares (MetricBase::kStaticSpherical, Metric::spherical_lens()).
struct SphericalLens {
  static constexpr int kMaxCoef = 5;
  double a[kMaxCoef] = {1, 0, 0, 0, 0};  // A(u) = sum a[k] u^k
  double h[kMaxCoef] = {1, 0, 0, 0, 0};  // h(u) = sum h[k] u^k
  // 1 / R of the innermost sphere the rays of this file may approach: the photon sphere of a black hole
  // (rays below the critical impact parameter fall in) or the throat of a wormhole (they pass through it
  // to the other sheet).
  double u_inner = 0.0;
  bool throat = false;

  // Schwarzschild's of mass m (A = 1 - 2m u, rays below the photon sphere u = 1/3m fall in): its own lens, and
  // the proxy of Kerr and of a line element that gives a mass.
  static SphericalLens schwarzschild(double m) {
    SphericalLens s;
    s.a[1] = -2.0 * m;
    s.u_inner = 1.0 / (3.0 * m);
    return s;
  }

  // M where P is Schwarzschild's cubic, 1 - b^2 u^2 + 2M b^2 u^3 (A = 1 - 2M u, h = 1), else 0: then its
  // integrals are Carlson's R_F of its roots (LensMap) and its orbits elliptic functions (planar_orbit.h).
  double cubic_mass() const {
    if (throat || a[0] != 1.0 || !(a[1] < 0.0) || h[0] != 1.0) return 0.0;
    for (int k = 2; k < kMaxCoef; ++k)
      if (a[k] != 0.0) return 0.0;
    for (int k = 1; k < kMaxCoef; ++k)
      if (h[k] != 0.0) return 0.0;
    return -0.5 * a[1];
  }
};

// One ray between two radii, found or evaluated: its emission angle psi at A, swept azimuth Phi, dPhi /
// dpsi, and dR/dphi where it reaches B (> 0 moving outward).
struct LensRay {
  bool ok = false;
  double psi = 0.0, phi = 0.0, dphi_dpsi = 0.0, dr_dphi = 0.0, b = 0.0;
  int evals = 0;  // evaluations of Phi that found it (LensMap::solve)
};

// One evaluation of a lens map at Newton's start z (LensMap::start_at), which LensMap::solve can begin from.
struct LensStart {
  double z = -1.0;
  bool ok = false;
  LensRay r;
  double dphi_dtau = 0.0;
};

class LensMap {
 public:
  using D1 = Dual<1>;

  // The rays from radius 1/uA on one sheet to radius 1/uB on the same sheet (same_sheet) or the other.
  LensMap(const SphericalLens& s, double uA, double uB, bool same_sheet) : s_(s), uA_(uA), uB_(uB) {
    if (!(uA > 0.0 && uB > 0.0) || uA >= s.u_inner * kInnerMargin || uB >= s.u_inner * kInnerMargin) return;
    for (int k = 0; k < SphericalLens::kMaxCoef; ++k) {
      if (s.a[k] != 0.0) na_ = k + 1;
      if (s.h[k] != 0.0) nh_ = k + 1;
    }
    np_ = na_ + nh_ + 2;  // P's coefficients 0 .. np_ - 1
    cubic_m_ = s.cubic_mass();
    AA_ = poly(s.a, uA);
    const double AB = poly(s.a, uB), Ai = poly(s.a, s.u_inner);
    if (!(AA_ > 0.0 && AB > 0.0 && Ai > 0.0)) return;
    bc_ = 1.0 / (s.u_inner * std::sqrt(Ai));
    const double sin_c = bc_ * uA * std::sqrt(AA_);  // sin of the critical emission angle at A
    if (!(sin_c < 1.0)) return;
    if (!same_sheet) {
      if (!s.throat) return;
      case_ = kThroat;  // tau = pi - psi in [0, asin(sin_c)): inward, through the throat
      tau_hi_ = std::asin(sin_c);
    } else if (uB <= uA) {
      case_ = kOutward;  // tau = psi in [0, pi - asin(sin_c)): outward, or inward round the periapsis
      tau_hi_ = M_PI - std::asin(sin_c);
    } else {
      case_ = kInward;  // tau = sigma, b = bB - sigma^2: inward to B (sigma < 0), or past the periapsis
      bB_ = 1.0 / (uB * std::sqrt(AB));
      if (!(bB_ > bc_)) return;
      tau_lo_ = -std::sqrt(bB_);
      tau_hi_ = std::sqrt(bB_ - bc_);
    }
    valid_ = true;
  }

  bool valid() const { return valid_; }

  // The ray that sweeps Phi = target: safeguarded Newton in z = -log(1 - (tau - tau_lo) / (tau_hi - tau_lo)),
  // in which Phi grows about linearly all the way (it diverges logarithmically in tau), started from
  // `guess` (a z; negative: the middle). Returns the ray and its z.
  //
  // Newton converges quadratically, so once the step from the last evaluation is small the root it lands
  // on is Phi = target to well below the tolerance, and the evaluation that would only confirm it is
  // skipped: the ray there is the one evaluated, moved on by the step (psi and b exactly, dPhi/dz from the
  // cubic through the last two evaluations; moved_ray). That takes 20-25 % of the evaluations out of the
  // order-0 and order-1 images of a room (3.7 and 2.7 per image against 4.6 and 3.5 from the same starts)
  // at a residual of Phi below 1e-10 relative, as before.
  //
  // `first` (from start_at(guess)) is the evaluation at the start, made already: it is used, not repeated.
  LensRay solve(double target, double guess = -1.0, double* z_out = nullptr, const LensStart* first = nullptr) const {
    LensRay none;
    if (!valid_ || !(target >= 0.0)) return none;
    const double span = tau_hi_ - tau_lo_, tol = 1e-10 * std::max(1.0, target);
    double lo = 0.0, hi = INFINITY;
    double z = first ? first->z : guess >= 0.0 ? guess : std::log(2.0);
    double z_prev = NAN, f_prev = NAN, slope_prev = NAN;  // the last evaluation's z, Phi - target, dPhi/dz
    for (int it = 0; it < 60; ++it) {
      const double tau = tau_at(z);
      LensRay r;
      double dphi_dtau = 0.0;
      double next;
      bool evaluated;
      if (it == 0 && first) {
        evaluated = first->ok;
        r = first->r;
        dphi_dtau = first->dphi_dtau;
      } else {
        evaluated = tau < tau_hi_ && eval(tau, r, &dphi_dtau);
      }
      if (!evaluated) {
        hi = z;  // only the far end (rays that fall in, or rounding there) can fail
        next = 0.5 * (lo + hi);
        z_prev = NAN;
      } else {
        const double f = r.phi - target;
        r.evals = it + 1;
        if (std::fabs(f) <= tol) {  // B to ~1e-10 of its radius
          if (z_out) *z_out = z;
          return r;
        }
        if (f < 0.0) lo = z; else hi = z;
        if (hi - lo <= 1e-14 * std::max(1.0, z)) {
          // Rounding at the fold of an inward case (a ray grazing B's sphere) limits Phi to ~1e-9.
          if (std::fabs(f) > 1e-8 * std::max(1.0, target)) return none;
          if (z_out) *z_out = z;
          return r;
        }
        const double dphi_dz = dphi_dtau * span * std::exp(-z);
        next = dphi_dz > 0.0 ? z - f / dphi_dz : -1.0;
        if (next > lo && next < hi && std::isfinite(z_prev) && std::fabs(f) <= 1e-5 * std::max(1.0, target)) {
          // Phi's curvature in z at z from the cubic through the last two evaluations (values and slopes);
          // the step's residual is about curv step^2 / 2.
          const double w = z - z_prev, step = next - z;
          const double curv = (6.0 * (f_prev - f) + w * (2.0 * slope_prev + 4.0 * dphi_dz)) / (w * w);
          LensRay moved;
          // (from evaluations close together: from far apart the cubic's curvature misses by ~1e-1, the
          // slope by ~1e-7)
          if (std::fabs(w) <= 0.3 && std::isfinite(curv) && 0.5 * std::fabs(curv) * step * step <= 0.1 * tol &&
              moved_ray(tau_at(z_prev), tau, next, target, dphi_dz + curv * step, moved)) {
            if (z_out) *z_out = next;
            moved.evals = it + 1;
            return moved;
          }
        }
        z_prev = z;
        f_prev = f;
        slope_prev = dphi_dz;
        if (!(next > lo && next < hi)) next = std::isfinite(hi) ? 0.5 * (lo + hi) : 2.0 * z + 1.0;
      }
      z = next;
    }
    return none;
  }

  // The map evaluated once at z (as solve's iterations evaluate it): the ray there and dPhi/dtau; ok false where
  // the evaluation fails. What a later order's weight is estimated from before deciding to solve it.
  LensStart start_at(double z) const {
    LensStart s;
    s.z = z;
    if (!valid_ || !(z >= 0.0)) return s;
    const double tau = tau_at(z);
    s.ok = tau < tau_hi_ && eval(tau, s.r, &s.dphi_dtau);
    return s;
  }

  // The ray one Newton step on from start s towards the root Phi = target, without evaluating Phi there: psi and b
  // exactly, Phi = target and dPhi/dz taken from the start (moved_ray). What a later image's weight is estimated
  // from: |dPhi/dpsi| grows about as e^z towards the critical ray, so the start's own ray (one Newton step short)
  // overestimates the image's weight 0.9-2.6x in fig07's pairs, this ray by 1-4 %. False (solve instead) where
  // the step leaves the start's branch or is longer than kEstimateStep in z: from farther (a hole of 1e-12 M in
  // a room, where the root is lost in rounding) the estimate is anything (measured: within 9 % up to a step of
  // 1, 17 % up to 3, off by e^45 beyond).
  static constexpr double kEstimateStep = 1.0;
  bool newton_estimate(const LensStart& s, double target, LensRay& r) const {
    if (!s.ok) return false;
    const double span = tau_hi_ - tau_lo_;
    const double slope = s.dphi_dtau * span * std::exp(-s.z);  // dPhi/dz
    if (!(slope > 0.0)) return false;
    const double step = (target - s.r.phi) / slope, z = s.z + step;
    if (!(std::fabs(step) <= kEstimateStep && z >= 0.0)) return false;
    const double tau = tau_at(s.z);
    return moved_ray(tau, tau, z, target, slope, r);
  }

  // A later order's ray estimated from an earlier order's start s (start_at, evaluated, that order's image at Phi =
  // prev) without evaluating the map again, where P is Schwarzschild's cubic. Along a branch Phi diverges as
  // -log(b - b_c) with b - b_c linear in tau_hi - tau, so Phi's slope in z tends to 1; from s's Newton root z_p with
  // slope s', the image of Phi = target is taken at z_p + dz with dz + (s' - 1)(1 - e^-dz) = target - prev (the
  // slope relaxing to 1 as 1 + (s' - 1) e^-dz), and its ray moved there as newton_estimate's is. The start of order 1
  // already lies where the slope is near 1, so order 2's weight comes to 0.3-4 % (medians; within 27 % of the exact
  // one over 40,000 random pairs round holes of 1 to 8 units in a box of 100) for no evaluation; a weight is only the
  // probability of drawing an image, which is then solved (its Jacobian exact). False (evaluate instead) off the
  // cubic, where s' is more than kExtrapolateSlope from 1 (a light mass for its distances: the branch is not yet
  // logarithmic, and the estimate would be anything) or s's own Newton step is longer than kEstimateStep. z: where
  // the estimate puts the image (a start for solving it).
  static constexpr double kExtrapolateSlope = 0.2;
  bool extrapolated_estimate(const LensStart& s, double prev, double target, LensRay& r, double& z) const {
    if (!(cubic_m_ > 0.0) || !s.ok || !(target > prev)) return false;
    const double slope = s.dphi_dtau * (tau_hi_ - tau_lo_) * std::exp(-s.z);
    const double k = slope - 1.0;
    if (!(std::fabs(k) <= kExtrapolateSlope)) return false;
    const double zp = s.z + (prev - s.r.phi) / slope;
    if (!(std::fabs(zp - s.z) <= kEstimateStep && zp >= 0.0)) return false;
    const double gain = target - prev;
    double dz = gain;
    for (int it = 0; it < 4; ++it) {  // Newton on dz + k (1 - e^-dz) = gain (its slope 1 + k e^-dz >= 0.8)
      const double e = std::exp(-dz);
      dz -= (dz + k * (1.0 - e) - gain) / (1.0 + k * e);
    }
    z = zp + dz;
    if (!std::isfinite(z)) return false;
    return moved_ray(tau_at(s.z), tau_at(zp), z, target, 1.0 + k * std::exp(-dz), r);
  }

  // The ray that leaves A at angle psi from the outward radial direction, evaluated forward (no root): its swept
  // azimuth Phi to B's radius and dPhi/dpsi. Not ok where it does not reach B's radius on this map's sheet (it
  // falls in, or passes the throat where B is on A's sheet), or for B inside A's radius (the inward case).
  LensRay at_psi(double psi) const {
    LensRay r;
    if (!valid_ || case_ == kInward) return r;
    const double tau = case_ == kThroat ? M_PI - psi : psi;
    double dphi_dtau = 0.0;
    if (!(tau >= tau_lo_ && tau < tau_hi_) || !eval(tau, r, &dphi_dtau)) r.ok = false;
    return r;
  }

  // The segment A -> B in the plane of A, B and the centre (A on the x axis, B at angle gamma): d = B - A, and
  // whether the line's closest point to the centre lies between A and B (A.d < 0 < B.d).
  struct FlatLine {
    double dx, dy;
    bool passes_closest;
  };
  FlatLine flat_line(double gamma) const {
    const double RA = 1.0 / uA_, RB = 1.0 / uB_, c = std::cos(gamma), s = std::sin(gamma);
    const double dx = RB * c - RA, dy = RB * s;
    return {dx, dy, RA * dx < 0.0 && dx * RB * c + dy * RB * s > 0.0};
  }

  // z of the order-0 image's start. A line that passes its point closest to the centre between A and B (most
  // room pairs) leaves A turned away from the centre by the angle that the first-order (Born) deflection along the
  // straight line gives the string through A and B: the transverse pull 2M b / r^3 per unit length, r^2 = b^2 +
  // s^2 at s along the line from its closest point (s_A < 0 < s_B), bends the line's direction at A by
  //   (2M / b) [s_B (s_B / r_B - s_A / r_A) + b (b / r_B - b / r_A)] / (s_B - s_A),
  // taken at 1.02 - 1.6 M / b of it (at least 0.3: the strong field's share is smaller; fitted on room pairs).
  // Other pairs, and a start at the fold of the inward case, take the straight line aimed short of B by 0.8 of
  // the bending that the line's own b gets to first order, (2M / b)(cos a_A + cos a_B) passing the closest point,
  // (2M / b)|cos a_A - cos a_B| not (sin a = b / R at either end; bent_line_guess). Room pairs of a
  // Schwarzschild hole (scratch driver, 100,000 pairs in a box of 100 around M = 2.5 / 1 / 5): 2.73 / 2.52 /
  // 3.10 Newton evaluations to the root, 3.04 / 2.97 / 3.15 from the bent line alone, 3.7 from the straight line.
  double direct_guess(double gamma) const {
    const double M = -0.5 * s_.a[1];
    if (!valid_ || s_.throat || !(M > 0.0)) return flat_guess(gamma);
    const FlatLine l = flat_line(gamma);
    const double len = std::sqrt(l.dx * l.dx + l.dy * l.dy);
    if (!(len > 0.0)) return flat_guess(gamma);
    const double RA = 1.0 / uA_, b = RA * std::fabs(l.dy) / len;
    if (l.passes_closest && b > 2.5 * M) {
      const double sa = RA * l.dx / len, sb = sa + len;
      const double ra = std::sqrt(b * b + sa * sa), rb = std::sqrt(b * b + sb * sb);
      const double turn = 2.0 * M / b * (sb * (sb / rb - sa / ra) + b * (b / rb - b / ra)) / len;
      // (the centre lies to the left of the line, dy > 0: turning away from it lowers the direction's angle psi)
      const double z = line_z(std::atan2(l.dy, l.dx) - std::max(0.3, 1.02 - 1.6 * M / b) * turn, true);
      if (z >= 0.0) return z;
    }
    return bent_line_guess(gamma, l, b, M);
  }

  // The straight line l from A to B (impact parameter b) aimed short of B by 0.8 of its first-order bending in
  // mass M (direct_guess).
  double bent_line_guess(double gamma, const FlatLine& l, double b, double M) const {
    const double ca = std::sqrt(std::max(0.0, 1.0 - b * b * uA_ * uA_)),
                 cb = std::sqrt(std::max(0.0, 1.0 - b * b * uB_ * uB_));
    const double bend = 2.0 * M / b * (l.passes_closest ? ca + cb : std::fabs(ca - cb));
    const double aim = gamma - 0.8 * bend;
    const double z = aim > 1e-6 && std::isfinite(aim) ? flat_guess(aim) : -1.0;
    return z >= 0.0 ? z : flat_guess(gamma);
  }

  // z of the ray leaving A at angle psi from the outward radial direction, on the branch of a line that passes its
  // closest point between A and B (passes_closest) or not; negative where there is none. In the inward case a b
  // at or beyond B's sphere's is taken as grazing it (clamp_fold), or refused where within 0.1 % of it (Newton
  // creeps from the fold: 50 evaluations instead of 3 from such starts).
  double line_z(double psi, bool passes_closest, bool clamp_fold = false) const {
    double tau;
    if (case_ == kOutward) {
      tau = psi;
    } else if (case_ == kThroat) {
      tau = M_PI - psi;
    } else {
      const double b = std::sin(psi) / (uA_ * std::sqrt(AA_));
      if (!clamp_fold && !(b < 0.999 * bB_)) return -1.0;
      tau = (passes_closest ? 1.0 : -1.0) * std::sqrt(std::max(0.0, bB_ - std::min(b, bB_)));
    }
    const double gap = (tau - tau_lo_) / (tau_hi_ - tau_lo_);
    if (!(gap > 0.0 && gap < 1.0)) return -1.0;
    return -std::log1p(-gap);
  }

  // z of the straight line from A to B seen as if space were flat (at angle gamma = AOB, short way):
  // the order-0 image's start.
  double flat_guess(double gamma) const {
    if (!valid_) return -1.0;
    const FlatLine l = flat_line(gamma);
    return line_z(std::atan2(l.dy, l.dx), l.passes_closest, true);  // the segment's angle from A's outward radial
  }

 private:
  // The branch parameter at z = -log(1 - (tau - tau_lo) / (tau_hi - tau_lo)) (solve's variable).
  double tau_at(double z) const { return tau_lo_ + (tau_hi_ - tau_lo_) * -std::expm1(-z); }

  enum Case { kOutward, kInward, kThroat };
  static constexpr double kInnerMargin = 1.0 / 1.02;  // radii within 2 % of the inner sphere are left out
  static constexpr int kNodes = 12;

  template <class T>
  static T poly(const double* c, T u) {
    T r = c[SphericalLens::kMaxCoef - 1];
    for (int k = SphericalLens::kMaxCoef - 2; k >= 0; --k) r = r * u + c[k];
    return r;
  }

  // P(u) = h(u) (1 - b^2 u^2 A(u)) as coefficients in u (degree < kP).
  static constexpr int kP = 2 * SphericalLens::kMaxCoef + 1;
  template <class T>
  void p_coefs(T b2, T p[kP]) const {
    T k[kP];
    for (int i = 0; i < kP; ++i) k[i] = T(0.0);
    k[0] = T(1.0);
    for (int i = 0; i < na_; ++i) k[i + 2] = k[i + 2] - b2 * s_.a[i];
    for (int i = 0; i < kP; ++i) p[i] = T(0.0);
    for (int i = 0; i < nh_; ++i)
      for (int j = 0; j < na_ + 2; ++j) p[i + j] = p[i + j] + k[j] * s_.h[i];
  }
  template <class T>
  T peval(const T p[kP], T u) const {
    T r = p[np_ - 1];
    for (int k = np_ - 2; k >= 0; --k) r = r * u + p[k];
    return r;
  }
  double pderiv(const double p[kP], double u) const {
    double r = 0.0;
    for (int k = np_ - 1; k >= 1; --k) r = r * u + k * p[k];
    return r;
  }

  // The turning point: the smallest root u_t of P in (0, u_inner] (P(0) = 1). False if none (the ray
  // falls in). through = the root is the throat.
  bool turning(const double p[kP], double b, double& ut, bool& through) const {
    through = false;
    const double ui = s_.u_inner;
    const double pi = peval(p, ui);
    double size = 0.0;  // of P's terms at the throat, where they cancel: its rounding error is ~1e-16 of it
    for (int k = np_ - 1; k >= 0; --k) size = size * ui + std::fabs(p[k]);
    if (s_.throat && std::fabs(pi) <= 1e-14 * size) {
      // The throat is always a root; a periapsis comes first if P dips below zero before it.
      double umin = 0.0;
      const double pmid = peval(p, ui * (1.0 - 1e-9));
      if (!(pmid < 0.0)) {
        ut = ui;
        through = true;
        return true;
      }
      return bracket_root(p, umin, ui * (1.0 - 1e-9), 1.0 / b, ut);
    }
    if (!(pi < 0.0)) return false;
    // The periapsis of a ray with b well above critical is near the flat one, u = 1 / b, beyond it.
    return bracket_root(p, 0.0, ui, 1.0 / b, ut);
  }
  bool bracket_root(const double p[kP], double lo, double hi, double guess, double& ut) const {
    // P(lo) > 0 > P(hi): Newton from the guess, bisection as the safeguard.
    double u = guess > lo && guess < hi ? guess : lo + 0.5 * (hi - lo);
    for (int it = 0; it < 100; ++it) {
      const double f = peval(p, u);
      if (f > 0.0) lo = u; else hi = u;
      const double d = pderiv(p, u);
      // Converged when Newton's own step is at the rounding level (near the root f is rounding noise, and
      // a step that rounds back onto u would otherwise be taken for one leaving the bracket).
      const double step = d != 0.0 ? f / d : NAN;
      if (std::fabs(step) <= 1e-15 * u) {
        ut = std::min(hi, std::max(lo, u - step));
        return true;
      }
      double next = d != 0.0 ? u - step : 0.5 * (lo + hi);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (std::fabs(next - u) <= 1e-15 * u || hi - lo <= 1e-15 * hi) {
        ut = next;
        return true;
      }
      u = next;
    }
    ut = u;
    return true;
  }

  // Gauss-Legendre nodes and weights on [-1, 1].
  static void gauss(double x[kNodes], double w[kNodes]) {
    static const double X[6] = {0.1252334085114689, 0.3678314989981802, 0.5873179542866175,
                                0.7699026741943047, 0.9041172563704749, 0.9815606342467192};
    static const double W[6] = {0.2491470458134028, 0.2334925365383548, 0.2031674267230659,
                                0.1600783285433462, 0.1069393259953184, 0.0471753363865118};
    for (int i = 0; i < 6; ++i) {
      x[i] = -X[i];
      x[11 - i] = X[i];
      w[i] = w[11 - i] = W[i];
    }
  }

  // Integral of 2 b / sqrt(D(t^2)) over t in [t1, t2] (0 <= t1 <= t2), graded towards t = 0 where D(0)
  // is small (near-critical rays).
  D1 turn_integral(const D1 c[kP], D1 b, D1 t1, D1 t2) const {
    double x[kNodes], w[kNodes];
    gauss(x, w);
    const double d0 = std::max(c[0].v, 0.0), d1 = std::fabs(c[1].v);
    const double width = d1 > 0.0 ? std::sqrt(d0 / d1) : 0.0;
    // Piece edges: t2, t2 q, t2 q^2, ... down to about the width of D's near-zero, then t1.
    double edges[kMaxPieces + 1];
    int n = 0;
    edges[n++] = t2.v;
    while (n < kMaxPieces && edges[n - 1] * kGrade > std::max(0.5 * width, t1.v)) {
      edges[n] = edges[n - 1] * kGrade;
      ++n;
    }
    D1 sum(0.0);
    for (int k = 0; k < n; ++k) {
      const D1 hi = k == 0 ? t2 : D1(edges[k]);
      const D1 lo = k == n - 1 ? t1 : D1(edges[k + 1]);
      const D1 half = (hi - lo) * 0.5, mid = (hi + lo) * 0.5;
      D1 part(0.0);
      for (int i = 0; i < kNodes; ++i) {
        const D1 t = mid + half * x[i], e = t * t;
        D1 d = c[np_ - 2];
        for (int j = np_ - 3; j >= 0; --j) d = d * e + c[j];
        const double r = 1.0 / std::sqrt(d.v);  // w / sqrt(d) and its derivative, one root and one division
        part.v += w[i] * r;
        part.d[0] -= 0.5 * w[i] * r * r * r * d.d[0];
      }
      sum = sum + part * half;
    }
    return sum * b * 2.0;
  }
  static constexpr int kMaxPieces = 24;
  static constexpr double kGrade = 0.2;

  // Integral of b / sqrt(P(u)) over u in [u1, u2] for a ray with no turning point (it falls in).
  D1 plain_integral(const D1 p[kP], D1 b, double u1, double u2) const {
    double x[kNodes], w[kNodes];
    gauss(x, w);
    D1 sum(0.0);
    for (int piece = 0; piece < 2; ++piece) {
      const double lo = u1 + (u2 - u1) * 0.5 * piece, hi = lo + (u2 - u1) * 0.5;
      for (int i = 0; i < kNodes; ++i) {
        const D1 u(0.5 * (lo + hi) + 0.5 * (hi - lo) * x[i]);
        const D1 d = peval(p, u);
        const double r = 1.0 / std::sqrt(d.v), wi = 0.5 * (hi - lo) * w[i];
        sum.v += wi * r;
        sum.d[0] -= 0.5 * wi * r * r * r * d.d[0];
      }
    }
    return sum * b;
  }

  // The ray at branch parameter tau before its sweep: impact parameter b and emission angle psi with their
  // tau-derivatives, whether it leaves A inward and whether it passes its turning point before reaching B.
  struct Branch {
    D1 b, psi;
    bool inward = false, after_turn = false;
  };
  bool branch(double tau_v, Branch& br) const {
    const D1 tau = D1::variable(tau_v, 0);
    const double sA = uA_ * std::sqrt(AA_);  // sin psi = b sA
    if (case_ == kInward) {
      br.b = D1(bB_) - tau * tau;
      if (!(br.b.v >= 0.0)) return false;
      const double s = std::min(1.0, br.b.v * sA);
      br.psi.v = M_PI - std::asin(s);
      br.psi.d[0] = -br.b.d[0] * sA / std::sqrt(std::max(1e-300, 1.0 - s * s));
      br.inward = true;
      br.after_turn = tau_v >= 0.0;
    } else {
      br.psi = case_ == kThroat ? D1(M_PI) - tau : tau;
      double sp, cp;
      sin_cos(br.psi.v, sp, cp);
      br.b.v = sp / sA;
      br.b.d[0] = cp * br.psi.d[0] / sA;
      br.inward = br.psi.v > 0.5 * M_PI;
      br.after_turn = br.inward;
    }
    return true;
  }

  // Phi, psi and their tau-derivatives for branch parameter tau; dR/dphi at B.
  bool eval(double tau_v, LensRay& r, double* dphi_dtau) const {
    Branch br;
    if (!branch(tau_v, br)) return false;
    const D1 b = br.b, psi = br.psi;
    const bool inward = br.inward, after_turn = br.after_turn;
    if (cubic_m_ > 0.0) {
      // Schwarzschild's cubic: the periapsis in closed form (light_cubic.h) and its derivative
      // du_t/db = -P_b / P_u = -u_t (1 - 2M u_t) / (b (1 - 3M u_t)), P = 1 - b^2 u^2 (1 - 2M u).
      const double M = cubic_m_, uv = LightCubic{M, b.v}.periapsis();
      if (uv > 0.0 && uv <= s_.u_inner) {
        D1 ut(uv);
        ut.d[0] = -uv * (1.0 - 2.0 * M * uv) / (b.v * (1.0 - 3.0 * M * uv)) * b.d[0];
        D1 phi;
        double root_p_b;  // sqrt(P(uB))
        if (!cubic_phi(b, ut, after_turn, phi, root_p_b)) return false;
        return finish(r, phi, psi, b, inward, after_turn, root_p_b, dphi_dtau);
      }
      if (after_turn) return false;  // (b below critical: the ray falls in; the quadrature below)
    }
    double p[kP];
    D1 pd[kP];
    p_coefs(b * b, pd);
    for (int i = 0; i < kP; ++i) p[i] = pd[i].v;
    double ut_v = 0.0;
    bool through = false;
    const bool turns = cubic_m_ > 0.0 ? false : turning(p, b.v, ut_v, through);
    // Through the throat: what a throat ray must do, and what a same-sheet ray may do only after reaching B
    // (an inward ray that meets B first).
    if (case_ == kThroat ? !(turns && through) : (turns && through && after_turn)) return false;
    if (after_turn && !turns) return false;
    D1 phi;
    double root_p_b;  // sqrt(P(uB))
    if (turns) {
      // u_t as a function of b: one Newton step in duals from the converged root (the throat is fixed).
      D1 ut(ut_v);
      if (!through) ut = ut - peval(pd, ut) / pderiv(p, ut_v);
      // Taylor shift: P(ut - e) = sum c_j e^j; D(e) = sum_{j >= 1} c_j e^(j - 1).
      D1 sh[kP];
      for (int i = 0; i < kP; ++i) sh[i] = pd[i];
      for (int i = 0; i < np_; ++i)  // synthetic division by (u - ut), repeated: coefficients of P(ut + e)
        for (int j = np_ - 2; j >= i; --j) sh[j] = sh[j] + ut * sh[j + 1];
      D1 c[kP];
      for (int j = 1; j < np_; ++j) c[j - 1] = (j % 2 ? -1.0 : 1.0) * sh[j];
      for (int j = np_ - 1; j < kP; ++j) c[j] = D1(0.0);
      D1 eA = ut - uA_, eB = ut - uB_;
      // A radius at the turning point itself (a ray that grazes B's sphere) can round to just inside it.
      if (eA.v < 0.0 && eA.v > -1e-12 * ut.v) eA = D1(0.0);
      if (eB.v < 0.0 && eB.v > -1e-12 * ut.v) eB = D1(0.0);
      if (!(eA.v >= 0.0 && eB.v >= 0.0)) return false;
      const D1 tA = eA.v > 0.0 ? sqrt(eA) : D1(0.0), tB = eB.v > 0.0 ? sqrt(eB) : D1(0.0);
      if (after_turn) {
        phi = turn_integral(c, b, D1(0.0), tA) + turn_integral(c, b, D1(0.0), tB);
      } else if (tA.v <= tB.v) {
        phi = turn_integral(c, b, tA, tB);
      } else {
        phi = turn_integral(c, b, tB, tA);
      }
      D1 dB = c[np_ - 2];
      for (int j = np_ - 3; j >= 0; --j) dB = dB * eB + c[j];
      root_p_b = tB.v * std::sqrt(std::max(0.0, dB.v));
    } else {
      phi = plain_integral(pd, b, std::min(uA_, uB_), std::max(uA_, uB_));
      root_p_b = std::sqrt(std::max(0.0, peval(p, uB_)));
    }
    return finish(r, phi, psi, b, inward, after_turn, root_p_b, dphi_dtau);
  }

  // The ray at z (branch parameter tau) found one Newton step from the one evaluated at tau_from: it sweeps
  // `target`, with dPhi/dz = slope there (from the evaluations at tau_prev and tau_from). False where these
  // three rays are not all on one branch (one turns round or leaves inward where another does not: Phi's
  // curvature jumps there): then the caller evaluates.
  bool moved_ray(double tau_prev, double tau_from, double z, double target, double slope, LensRay& r) const {
    const double tau = tau_at(z);
    Branch prev, from, br;
    if (!(tau < tau_hi_) || !branch(tau_prev, prev) || !branch(tau_from, from) || !branch(tau, br)) return false;
    for (const Branch* o : {&prev, &from})
      if (br.inward != o->inward || br.after_turn != o->after_turn) return false;
    if (!(slope > 0.0)) return false;
    // sqrt(P(u_B)) = sqrt(h (1 - b^2 u_B^2 A)) at B; at a ray grazing B's sphere it is ~0 either way.
    const double pB = poly(s_.h, uB_) * (1.0 - br.b.v * br.b.v * uB_ * uB_ * poly(s_.a, uB_));
    D1 phi(target);
    phi.d[0] = slope / ((tau_hi_ - tau_lo_) * std::exp(-z));  // dPhi/dtau
    return finish(r, phi, br.psi, br.b, br.inward, br.after_turn, std::sqrt(std::max(0.0, pB)), nullptr);
  }

  bool finish(LensRay& r, D1 phi, D1 psi, D1 b, bool inward, bool after_turn, double root_p_b,
              double* dphi_dtau) const {
    if (!std::isfinite(phi.v) || !std::isfinite(phi.d[0])) return false;
    const bool arrives_outward = after_turn || !inward;
    r.ok = true;
    r.psi = psi.v;
    r.phi = phi.v;
    r.b = b.v;
    r.dphi_dpsi = psi.d[0] != 0.0 ? phi.d[0] / psi.d[0] : INFINITY;
    r.dr_dphi = (arrives_outward ? 1.0 : -1.0) * root_p_b / (uB_ * uB_ * std::max(b.v, 1e-300));
    if (dphi_dtau) *dphi_dtau = phi.d[0];
    return true;
  }

  // Schwarzschild's cubic: Phi from A to B (after_turn: in to the turning point u2 and out again) by one
  // Carlson R_F of the roots u1 < 0 < u2 < u3 (u3 + u1 = 1/2M - u2, u3 u1 = -1 / (2M b^2 u2)), and
  // sqrt(P(uB)). The factors (u - u1), (u2 - u), (u3 - u) are positive between the radii. (The sweep round
  // the turning point as two R_F's, one from each radius, was 4.5 % of fig07's time more.)
  bool cubic_phi(D1 b, D1 u2, bool after_turn, D1& phi, double& root_p_b) const {
    const double M = cubic_m_;
    const D1 p = 0.5 / M - u2, c = 1.0 / (2.0 * M * b * b * u2);
    const D1 u3 = 0.5 * (p + sqrt(p * p + 4.0 * c)), u1 = -c / u3;
    if (!(u1.v < 0.0 && u3.v > u2.v)) return false;
    const double scale = 2.0 / std::sqrt(2.0 * M);  // b / sqrt(2M b^2), times R_F's 2
    auto factor_sqrt = [&](D1 u, D1& f1, D1& f2, D1& f3) {
      const D1 g2 = u2 - u;
      if (!(g2.v >= -1e-12 * u2.v)) return false;
      f1 = sqrt(u - u1);
      f2 = g2.v > 0.0 ? sqrt(g2) : D1(0.0);
      f3 = sqrt(u3 - u);
      return true;
    };
    // int_y^x (y < x) of du / sqrt((u - u1)(u2 - u)(u3 - u)), times b / sqrt(2M b^2)
    auto integral = [&](D1 x, D1 y) {
      D1 X1, X2, X3, Y1, Y2, Y3;
      if (!(x.v > y.v)) return D1(0.0);
      if (!factor_sqrt(x, X1, X2, X3) || !factor_sqrt(y, Y1, Y2, Y3)) return D1(NAN);
      const D1 d = x - y;
      const D1 U12 = (X1 * X2 * Y3 + Y1 * Y2 * X3) / d, U13 = (X1 * X3 * Y2 + Y1 * Y3 * X2) / d,
               U23 = (X2 * X3 * Y1 + Y2 * Y3 * X1) / d;
      return scale * carlson_rf(U12 * U12, U13 * U13, U23 * U23);
    };
    const D1 uA(uA_), uB(uB_);
    if (after_turn) {
      // In to the turning point u2 and out again: Carlson's integral from y = uB to x = uA along the path
      // round the branch point u2, where sqrt(u2 - u) changes sign, is one R_F of U12^2, U12^2 + (u3 - u2),
      // U12^2 + (u3 - u1) with U12 = (Y1 Y2 X3 - X1 X2 Y3) / (x - y), written without cancellation as
      // ((u3 - u2)(x + y - u1 - u2) - (u2 - x)(u2 - y)) / (X1 X2 Y3 + Y1 Y2 X3). Past the complete integral
      // C = int_u1^u2 (U12 crossing zero: rays that sweep far round) the sweep is 2 C minus that R_F's.
      D1 X1, X2, X3, Y1, Y2, Y3;
      if (!factor_sqrt(uA, X1, X2, X3) || !factor_sqrt(uB, Y1, Y2, Y3)) return false;
      const D1 den = X1 * X2 * Y3 + Y1 * Y2 * X3;
      if (!(den.v > 0.0)) {
        phi = D1(0.0);  // both radii at the turning point
      } else {
        const D1 q = (u3 - u2) * (uA + uB - u1 - u2) - (u2 - uA) * (u2 - uB);
        const D1 U = q / den, s = U * U;
        phi = scale * carlson_rf(s, s + (u3 - u2), s + (u3 - u1));
        if (q.v < 0.0) phi = 2.0 * scale * carlson_rf_complete(u3 - u2, u3 - u1) - phi;
      }
    } else {
      phi = uA_ >= uB_ ? integral(uA, uB) : integral(uB, uA);
    }
    const double gB = std::max(0.0, u2.v - uB_);
    root_p_b = b.v * std::sqrt(2.0 * M * (uB_ - u1.v) * gB * (u3.v - uB_));
    return std::isfinite(phi.v);
  }

  const SphericalLens& s_;
  double uA_, uB_, AA_ = 0.0, bc_ = 0.0, bB_ = 0.0;
  double tau_lo_ = 0.0, tau_hi_ = 0.0;
  double cubic_m_ = 0.0;
  int na_ = 1, nh_ = 1, np_ = 4;
  Case case_ = kOutward;
  bool valid_ = false;
};

}  // namespace wv
