// Observers that move: the 4-velocity of a camera that is not the local static observer (ZAMO, a circular
// geodesic orbit, radial free fall, a velocity relative to the local observer, or a 4-velocity given
// outright), with the reason where no such observer can be at a point, and its frame.
//
// The frame of a 4-velocity u is the Lowdin triad of the coordinate axes projected orthogonal to u
// (frame.h: lowdin_triad): the local observer's own frame when u is the local observer, in flat space the
// static frame boosted to u (a pure boost: aberration and Doppler shift exactly), and defined wherever u
// is timelike, inside a horizon too, so a falling camera's frame is continuous through it.
#pragma once

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "core/dual.h"
#include "core/linalg.h"
#include "spacetime/frame.h"

namespace wv {

enum class ObserverKind : int {
  kLocal = 0,  // the local static observer, the ZAMO inside an ergoregion (every render before observers)
  kStatic,     // at rest along d/dt: only where g_tt < 0
  kZamo,       // zero angular momentum about z, no radial motion
  kOrbit,      // a circular geodesic orbit about `axis` through the centre
  kFreeFall,   // radial free fall (zero angular momentum) from rest at `fall_from` (0: infinity)
  kMoving,     // `velocity` (units of c) relative to the local observer, in its frame's axes
  kGiven,      // the chart 4-velocity `u`, e.g. from a camera path integrated as a timelike geodesic
};

struct ObserverSpec {
  ObserverKind kind = ObserverKind::kLocal;
  double velocity[3] = {0.0, 0.0, 0.0};
  double axis[3] = {0.0, 0.0, 1.0};
  double fall_from = 0.0;
  double u[4] = {0.0, 0.0, 0.0, 0.0};
};

namespace observer_detail {

inline double dot4(const double g[4][4], const double a[4], const double b[4]) {
  double s = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) s += g[i][j] * a[i] * b[j];
  return s;
}

inline std::string num(double v) {
  std::ostringstream o;
  o.precision(6);
  o << v;
  return o.str();
}

// g^{mu nu} and g_{mu nu} at x; false where the metric is singular.
template <class M>
bool metrics_at(const M& m, const double x[4], double gi[4][4], double g[4][4]) {
  m.inverse_metric(x, gi);
  return invert4(gi, g);
}

// The unit vector along the timelike, future-directed (v^t > 0: t is a time function of every chart here)
// vector v; "" or why not.
inline std::string normalise_timelike(const double g[4][4], const double v[4], double u[4], const char* what) {
  const double n2 = dot4(g, v, v);
  if (!(n2 < 0.0)) return std::string("no ") + what + " here: it would move at or faster than light";
  if (!(v[0] > 0.0)) return std::string("no ") + what + " here: it would move backwards in time (u^t <= 0)";
  const double s = 1.0 / std::sqrt(-n2);
  for (int a = 0; a < 4; ++a) u[a] = v[a] * s;
  return "";
}

// Circular geodesic orbit about the unit axis a through the centre at chart point x (in the plane
// perpendicular to a): u = k / |k|, k = d_t + Omega xi, xi = a x x the rotation about a. A Killing
// vector's orbits are geodesics where grad(k.k) = 0; along the in-plane radial direction that is
// A + 2 Omega B + Omega^2 C = 0 (the radial derivatives of g_tt, g(d_t, xi), g(xi, xi), with xi's own
// derivative), taken exactly with dual numbers. The prograde root (Omega > 0 about a); the gradient's other
// components must vanish too (no pull out of the plane).
template <class M>
std::string orbit_velocity(const M& m, const double x[4], const double axis[3], double u[4]) {
  const double an = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  if (!(an > 0.0)) return "the orbit's axis must not be zero";
  const double a[3] = {axis[0] / an, axis[1] / an, axis[2] / an};
  const double r = std::sqrt(x[1] * x[1] + x[2] * x[2] + x[3] * x[3]);
  const double off = x[1] * a[0] + x[2] * a[1] + x[3] * a[2];
  if (!(r > 0.0)) return "a circular orbit needs a position away from the centre";
  if (std::fabs(off) > 1e-9 * r)
    return "a circular orbit about axis [" + num(a[0]) + ", " + num(a[1]) + ", " + num(a[2]) +
           "] lies in the plane through the centre perpendicular to it; the position is " + num(off) + " off it";
  using D = Dual<4>;
  D xd[4];
  for (int k = 0; k < 4; ++k) xd[k] = D::variable(x[k], k);
  D gid[4][4];
  m.inverse_metric(xd, gid);
  double gi[4][4], g[4][4];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) gi[i][j] = gid[i][j].v;
  if (!invert4(gi, g)) return "the metric is singular here";
  // dg_ab / dx^k = -g_ac (d g^cd / dx^k) g_db
  double dg[4][4][4];
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        double s = 0.0;
        for (int c = 0; c < 4; ++c)
          for (int d = 0; d < 4; ++d) s += g[i][c] * gid[c][d].d[k] * g[d][j];
        dg[k][i][j] = -s;
      }
  double xi[4] = {0.0, a[1] * x[3] - a[2] * x[2], a[2] * x[1] - a[0] * x[3], a[0] * x[2] - a[1] * x[1]};
  double A[4], B[4], C[4];  // d/dx^k of g_tt, g(d_t, xi), g(xi, xi), k = 1..3
  for (int k = 1; k < 4; ++k) {
    double dxi[4] = {0.0, 0.0, 0.0, 0.0};  // d xi / dx^k = a x e_k
    const double e[3] = {k == 1 ? 1.0 : 0.0, k == 2 ? 1.0 : 0.0, k == 3 ? 1.0 : 0.0};
    dxi[1] = a[1] * e[2] - a[2] * e[1];
    dxi[2] = a[2] * e[0] - a[0] * e[2];
    dxi[3] = a[0] * e[1] - a[1] * e[0];
    A[k] = dg[k][0][0];
    B[k] = 0.0;
    C[k] = 0.0;
    for (int i = 1; i < 4; ++i) {
      B[k] += dg[k][0][i] * xi[i] + g[0][i] * dxi[i];
      for (int j = 1; j < 4; ++j) C[k] += dg[k][i][j] * xi[i] * xi[j] + 2.0 * g[i][j] * xi[i] * dxi[j];
    }
  }
  double Ar = 0.0, Br = 0.0, Cr = 0.0;
  for (int k = 1; k < 4; ++k) {
    const double rk = x[k] / r;
    Ar += rk * A[k];
    Br += rk * B[k];
    Cr += rk * C[k];
  }
  const double disc = Br * Br - Ar * Cr;
  if (!(disc >= 0.0) || Cr == 0.0) return "no circular geodesic orbit about this axis here";
  const double sq = std::sqrt(disc);
  const double om1 = (-Br + sq) / Cr, om2 = (-Br - sq) / Cr;
  const double om = om1 > 0.0 && (om2 <= 0.0 || om1 < om2) ? om1 : om2;
  if (!(om > 0.0)) return "no prograde circular geodesic orbit about this axis here";
  double scale = 0.0, resid = 0.0;
  for (int k = 1; k < 4; ++k) {
    resid = std::max(resid, std::fabs(A[k] + 2.0 * om * B[k] + om * om * C[k]));
    scale = std::max(scale, std::fabs(A[k]) + 2.0 * om * std::fabs(B[k]) + om * om * std::fabs(C[k]));
  }
  if (resid > 1e-8 * scale)
    return "no circular geodesic orbit about this axis here: gravity pulls out of the orbit's plane "
           "(an axisymmetric spacetime's orbits lie in its equatorial plane)";
  const double k[4] = {1.0, om * xi[1], om * xi[2], om * xi[3]};
  return normalise_timelike(g, k, u, "circular orbit");
}

// Radial free fall with zero angular momentum: u_mu = (-E, kappa dr/dx^i), r the metric's radius, so u has
// no angular components (in Kerr these are Doran's observers). E = 1 from rest at infinity; from rest at
// r0 the E that makes r0 a turning point on the same radial line. Of the two roots kappa the one falling
// (dr/dtau < 0), which is regular through a horizon of a chart that crosses it.
template <class M>
std::string free_fall_velocity(const M& m, const double x[4], double fall_from, double u[4]) {
  auto grad_r = [&](const double p[4], double gr[3]) {
    const double r = m.radius(p);
    const double h = 1e-3 * std::max(1e-3, r);
    for (int i = 0; i < 3; ++i) {  // fourth-order central differences
      double q[4][4];
      const double off[4] = {-2.0 * h, -h, h, 2.0 * h};
      double f[4];
      for (int s = 0; s < 4; ++s) {
        for (int k = 0; k < 4; ++k) q[s][k] = p[k];
        q[s][i + 1] += off[s];
        f[s] = m.radius(q[s]);
      }
      gr[i] = (f[0] - 8.0 * f[1] + 8.0 * f[2] - f[3]) / (12.0 * h);
    }
  };
  // g^{tt}, g^{ti} dr_i, g^{ij} dr_i dr_j at p
  auto parts = [&](const double p[4], double gi[4][4], double gr[3], double& gtt, double& gtr, double& grr) {
    m.inverse_metric(p, gi);
    grad_r(p, gr);
    gtt = gi[0][0];
    gtr = 0.0;
    grr = 0.0;
    for (int i = 0; i < 3; ++i) {
      gtr += gi[0][i + 1] * gr[i];
      for (int j = 0; j < 3; ++j) grr += gi[i + 1][j + 1] * gr[i] * gr[j];
    }
  };
  const double r = m.radius(x);
  double E = 1.0;
  if (fall_from > 0.0) {
    if (r > fall_from * (1.0 + 1e-12))
      return "a camera falling from rest at r = " + num(fall_from) + " cannot be at r = " + num(r) +
             " (above it)";
    // the point of the same radial line at radius r0 (radius grows along the scaled chart point)
    double lo = 1.0, hi = 2.0, p[4] = {x[0], x[1], x[2], x[3]};
    auto at = [&](double s) {
      for (int k = 1; k < 4; ++k) p[k] = x[k] * s;
      return m.radius(p) - fall_from;
    };
    for (int i = 0; i < 200 && at(hi) < 0.0; ++i) hi *= 2.0;
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (lo + hi);
      (at(mid) < 0.0 ? lo : hi) = mid;
    }
    at(0.5 * (lo + hi));
    double gi0[4][4], gr0[3], gtt, gtr, grr;
    parts(p, gi0, gr0, gtt, gtr, grr);
    const double den = gtr * gtr - grr * gtt;
    if (!(grr > 0.0 && den > 0.0))
      return "no observer can be at rest at r = " + num(fall_from) + " (inside a horizon or an ergoregion)";
    E = std::sqrt(grr / den);
  }
  double gi[4][4], gr[3], gtt, gtr, grr;
  parts(x, gi, gr, gtt, gtr, grr);
  if (!(gr[0] * gr[0] + gr[1] * gr[1] + gr[2] * gr[2] > 0.0)) return "no radial direction here";
  double disc = E * E * gtr * gtr - grr * (gtt * E * E + 1.0);
  const double disc_scale = E * E * gtr * gtr + std::fabs(grr) * (std::fabs(gtt) * E * E + 1.0);
  if (disc < 0.0 && disc > -1e-12 * disc_scale) disc = 0.0;  // at rest at r0 itself, up to rounding
  if (!(disc >= 0.0)) return "no radial free fall from there reaches this point";
  const double sq = std::sqrt(disc);
  double kappa;
  if (E * gtr >= 0.0 && E * gtr + sq > 0.0)
    kappa = (gtt * E * E + 1.0) / (E * gtr + sq);  // the same root, without cancellation
  else if (grr != 0.0)
    kappa = (E * gtr - sq) / grr;
  else
    return "no radial free fall reaches this point";
  const double ul[4] = {-E, kappa * gr[0], kappa * gr[1], kappa * gr[2]};
  double v[4];
  for (int a = 0; a < 4; ++a) {
    v[a] = 0.0;
    for (int b = 0; b < 4; ++b) v[a] += gi[a][b] * ul[b];
  }
  double g[4][4];
  if (!invert4(gi, g)) return "the metric is singular here";
  return normalise_timelike(g, v, u, "free fall");
}

}  // namespace observer_detail

// The 4-velocity u^mu (chart components) of the observer `s` at chart point x; "" or why no such observer
// can be there.
template <class M>
std::string observer_velocity_of(const M& m, const double x[4], const ObserverSpec& s, double u[4]) {
  using namespace observer_detail;
  double gi[4][4], g[4][4];
  if (!metrics_at(m, x, gi, g)) return "the metric is singular here";
  switch (s.kind) {
    case ObserverKind::kLocal:
      if (!observer_velocity(m, x, g, u)) return "no static observer or ZAMO here (inside a horizon)";
      return "";
    case ObserverKind::kStatic: {
      if (!(g[0][0] < 0.0))
        return "no static observer here: g_tt >= 0 (inside an ergoregion or a horizon); a ZAMO "
               "(observer = \"zamo\") or a moving observer can be here";
      const double v[4] = {1.0, 0.0, 0.0, 0.0};
      return normalise_timelike(g, v, u, "static observer");
    }
    case ObserverKind::kZamo:
      return zamo_velocity(g, x, u) ? "" : "no zero-angular-momentum observer here (inside a horizon)";
    case ObserverKind::kOrbit:
      return orbit_velocity(m, x, s.axis, u);
    case ObserverKind::kFreeFall:
      return free_fall_velocity(m, x, s.fall_from, u);
    case ObserverKind::kMoving: {
      const double b2 = s.velocity[0] * s.velocity[0] + s.velocity[1] * s.velocity[1] + s.velocity[2] * s.velocity[2];
      if (!(b2 < 1.0))
        return "a speed of " + num(std::sqrt(b2)) + " c relative to the local observer is not below the speed of light";
      ObserverFrame f;
      if (!observer_frame(m, x, f))
        return "no static observer or ZAMO here (inside a horizon) to give a velocity relative to";
      const double gam = 1.0 / std::sqrt(1.0 - b2);
      for (int a = 0; a < 4; ++a) {
        u[a] = f.u[a];
        for (int j = 0; j < 3; ++j) u[a] += s.velocity[j] * f.e[j][a];
        u[a] *= gam;
      }
      return "";
    }
    case ObserverKind::kGiven: {
      const double n2 = dot4(g, s.u, s.u);
      if (!(std::fabs(n2 + 1.0) < 1e-6))
        return "a 4-velocity must have g(u, u) = -1, got " + num(n2);
      return normalise_timelike(g, s.u, u, "observer with this 4-velocity");
    }
  }
  return "unknown observer kind";
}

// The frame of the observer `s` at chart point x (spacetime/frame.h's ObserverFrame); "" or why not.
template <class M>
std::string observer_frame_of(const M& m, const double x[4], const ObserverSpec& s, ObserverFrame& f) {
  if (s.kind == ObserverKind::kLocal)
    return observer_frame(m, x, f) ? "" : "no static observer or ZAMO here (inside a horizon)";
  double gi[4][4];
  if (!observer_detail::metrics_at(m, x, gi, f.g)) return "the metric is singular here";
  const std::string why = observer_velocity_of(m, x, s, f.u);
  if (!why.empty()) return why;
  return lowdin_triad(f) ? "" : "the coordinate axes are degenerate for this observer";
}

}  // namespace wv
