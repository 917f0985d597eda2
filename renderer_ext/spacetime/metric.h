// The Metric contract.
//
// A metric is one struct in one .cpp file (its line element in the header comment) that derives from
// MetricBase<Self> and provides, in signature (-,+,+,+) with geometric units G = c = 1:
//
//   static constexpr const char* kName;                       registry name, e.g. "kerr"
//   static constexpr const char* kClassName;                  Python class name, e.g. "Kerr"
//   static constexpr const char* kSummary;                    one line for docs and the viewer's title
//   static constexpr ParamSpec kParams[];  kNumParams         parameters with ranges and defaults (params.h),
//                                                             in constructor order; the registry validates
//                                                             them before `explicit M(const std::vector<double>&)`
//   static constexpr int kNumInvariants;                      conserved quantities, [0] is always H
//   static constexpr const char* kInvariantNames[];           e.g. {"H", "E", "Lz", "Q"}
//   template <class T> void inverse_metric(const T x[4], T gi[4][4]) const;
//                                                             g^{mu nu}(x); T is double or Dual<4>
//   double radius(const double x[4]) const;                   areal / Boyer-Lindquist radius
//   void conserved(const double y[8], const HamiltonianParts& hp, double out[], double mag[]) const;
//                                                             conserved quantities 1..K-1 at state y, given
//                                                             the parts of H there (hamiltonian_parts or,
//                                                             at no cost, hamiltonian_parts_from_rhs;
//                                                             out[0], H, is filled by invariants()) and,
//                                                             if mag is not null, the size of the terms
//                                                             each is computed from (its rounding scale)
//   void invariant_scales(const double y[8], const double inv[], double scale[]) const;
//                                                             normalisation of each relative drift
//
//   Landmarks landmarks() const;                              horizon, capture radius, photon sphere or
//                                                             region, ergosurface, throat (landmarks.h);
//                                                             a black hole must set `capture` (contract test)
//
// and may override the defaults of MetricBase: a relation between parameters (`param_relation_problem`,
// documented by kParamRelation, e.g. |Q| < M), a hand-written Hamiltonian right-hand side `rhs`
// (checked against `rhs_autodiff` to 1e-12 by the contract tests), a horizon (`absorbed`,
// `horizon_radius`; `kChartCrossesHorizon = false` for a chart that ends at the horizon), a radius rays escape
// at in a spacetime that is not asymptotically flat (`escape_limit`), a chart change between sheets
// (`normalize_chart`, Ellis), and the map between the
// integration chart and the Cartesian frame the user sees (`chart_to_user`, `user_to_chart`), and, for a
// static spherically symmetric metric, `kStaticSpherical = true` with `spherical_lens()` (lens_map.h:
// A(u) and h(u) with ds^2 = -A dt^2 + dR^2 / (A h) + R^2 dOmega^2, u = 1 / R; the contract tests check
// them against the metric's own geodesics).
//
// The state of a ray is y = (x^0..x^3, p_0..p_3) with x^0 = t and Cartesian x^1..x^3; the Hamiltonian
// is H = 1/2 g^{mu nu} p_mu p_nu and Hamilton's equations dx^mu/dlambda = dH/dp_mu,
// dp_mu/dlambda = -dH/dx^mu are the geodesic equations. All metrics here are stationary, so p_0 = -E
// is constant.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>

#include "core/dual.h"
#include "core/vec3.h"
#include "spacetime/landmarks.h"
#include "spacetime/lens_map.h"
#include "spacetime/params.h"

namespace wv {

constexpr int kStateSize = 8;
constexpr int kMaxInvariants = 6;

// Hamilton's equations from the inverse metric alone, with exact derivatives from dual numbers.
template <class M>
void rhs_autodiff(const M& m, const double y[8], double dy[8]) {
  using D = Dual<4>;
  D x[4];
  for (int k = 0; k < 4; ++k) x[k] = D::variable(y[k], k);
  D gi[4][4];
  m.inverse_metric(x, gi);
  const double* p = y + 4;
  for (int mu = 0; mu < 4; ++mu) {
    double s = 0.0;
    for (int nu = 0; nu < 4; ++nu) s += gi[mu][nu].v * p[nu];
    dy[mu] = s;
  }
  for (int k = 0; k < 4; ++k) {
    double s = 0.0;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) s += gi[a][b].d[k] * p[a] * p[b];
    dy[4 + k] = -0.5 * s;
  }
}

// |2H| and the Euclidean size of its terms g^{mu nu} p_mu p_nu (their ratio is 0 for an exact null vector).
struct HamiltonianParts {
  double abs2h = 0.0, mag = 0.0, two_h = 0.0;  // |2H|, sum of |terms|, 2H
};

template <class M>
HamiltonianParts hamiltonian_parts(const M& m, const double y[8]) {
  double gi[4][4];
  m.inverse_metric(y, gi);
  double s = 0.0, mag = 0.0;
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) {
      const double t = gi[a][b] * y[4 + a] * y[4 + b];
      s += t;
      mag += std::fabs(t);
    }
  return {std::fabs(s), mag, s};
}

// The same parts from a state and its Hamilton derivative f = rhs(y), at no extra metric evaluation:
// dx^mu/dlambda = g^{mu nu} p_nu, so p_mu dx^mu/dlambda = 2H.
inline HamiltonianParts hamiltonian_parts_from_rhs(const double y[8], const double f[8]) {
  double s = 0.0, mag = 0.0;
  for (int a = 0; a < 4; ++a) {
    const double t = y[4 + a] * f[a];
    s += t;
    mag += std::fabs(t);
  }
  return {std::fabs(s), mag, s};
}

// Angular momentum L = x cross p (the rotation Killing fields contracted with p), Cartesian charts.
inline void angular_momentum(const double y[8], double l[3]) {
  l[0] = y[2] * y[7] - y[3] * y[6];
  l[1] = y[3] * y[5] - y[1] * y[7];
  l[2] = y[1] * y[6] - y[2] * y[5];
}

// Scale of the relative energy drift: |E|, or 1e-3 of the momentum's size where E is near zero
// (negative-energy orbits in an ergoregion).
inline double energy_scale(const double y[8], double energy) {
  const double pmag = std::sqrt(y[4] * y[4] + y[5] * y[5] + y[6] * y[6] + y[7] * y[7]);
  return std::fmax(std::fabs(energy), 1e-3 * pmag);
}

// The conserved quantities of a spherically symmetric metric in a Cartesian chart, invariants {H, E, Lz, L2}:
// E = -p_t, Lz and L^2 = |x cross p|^2 into out[1..3] (and their rounding scales into mag, if not null).
inline void spherical_conserved(const double y[8], double out[], double mag[]) {
  double l[3];
  angular_momentum(y, l);
  out[1] = -y[4];
  out[2] = l[2];
  out[3] = l[0] * l[0] + l[1] * l[1] + l[2] * l[2];
  if (mag) {
    const double xp = std::sqrt((y[1] * y[1] + y[2] * y[2] + y[3] * y[3]) * (y[5] * y[5] + y[6] * y[6] + y[7] * y[7]));
    mag[1] = std::fabs(y[4]);
    mag[2] = std::fabs(y[1] * y[6]) + std::fabs(y[2] * y[5]);
    mag[3] = xp * xp;
  }
}

// Normalisation of their relative drifts for a mass scale M.
inline void spherical_scales(const double y[8], const double inv[], double M, double scale[]) {
  scale[0] = 1.0;
  scale[1] = energy_scale(y, inv[1]);
  scale[2] = std::max(std::fabs(inv[2]), M * scale[1]);
  scale[3] = std::max(inv[3], M * M * scale[1] * scale[1]);
}

template <class Derived>
struct MetricBase {
  // Flat metrics trace straight lines analytically and never step.
  static constexpr bool kFlat = false;
  // The integration chart's x, y, z are the user's Cartesian coordinates (false: Ellis).
  static constexpr bool kUserIsChart = true;
  // Whether the chart reaches through the horizon (the Kerr-Schild charts do), so that a ray going forward
  // in time steps to the horizon itself. Where it does not (a static chart, whose g_rr diverges there: a
  // line element written in Schwarzschild coordinates), every ray is absorbed when it moves inward through
  // the capture radius, as camera rays always are (geodesic.h).
  static constexpr bool kChartCrossesHorizon = true;

  // Static and spherically symmetric, with its lens map's functions in spherical_lens() (lens_map.h):
  // the light connection then samples every image of a light exactly (integrators/lens_connection.h).
  static constexpr bool kStaticSpherical = false;
  SphericalLens spherical_lens() const { return {}; }
  // A metric close to a static spherical one far out (Kerr, a line element with a mass: Schwarzschild of the
  // same mass) may offer that one's lens map as a proxy: the light connection draws its directions from it as
  // a proposal (integrators/lens_proposal.h), and the image proxies start their Newton search there.
  static constexpr bool kLensProxy = false;
  SphericalLens lens_proxy() const { return {}; }
  // How far (user-frame length) this metric's images of a light point may lie from the proxy's: the proposal
  // grows each light by it, so that the directions by which light really arrives are the proposal's too, not
  // BSDF sampling's alone (lens_proposal.h, ProposalLight). Negative: not known (the proposal's default).
  double lens_proxy_margin() const { return -1.0; }
  // The spin vector (user frame, length units: Kerr's a along its axis) by which the proxy's mass differs from
  // orbit to orbit (zero: one mass), and that mass for light whose angular momentum makes cosine c with the spin
  // (integrators/lens_proposal.h, ProxyMass).
  V3 lens_proxy_spin() const { return {}; }
  double lens_proxy_mass(double c) const {
    (void)c;
    return 0.0;
  }

  // Sheets of the spacetime the user sees as separate Cartesian frames (2: a wormhole's two sides).
  static constexpr int kSheets = 1;
  static constexpr int kNumParams = 0;
  static constexpr const ParamSpec* kParams = nullptr;
  // A constraint between parameters that their ranges cannot express, in words ("" if none), and its check:
  // empty if the (range-checked) values p satisfy it, otherwise why not.
  static constexpr const char* kParamRelation = "";
  static std::string param_relation_problem(const double* /*p*/) { return {}; }

  const Derived& self() const { return static_cast<const Derived&>(*this); }

  // Landmark radii; metrics add photon orbits, ergosurface, throat and their mass scale.
  Landmarks landmarks() const {
    Landmarks l;
    l.horizon = self().horizon_radius();
    l.capture = self().capture_radius();
    l.escape = self().escape_limit();
    return l;
  }

  // Hamilton's equations; metrics override this with a hand-written version for speed.
  void rhs(const double y[8], double dy[8]) const { rhs_autodiff(self(), y, dy); }

  // All invariants: out[0] = H, then the metric's conserved quantities.
  void invariants(const double y[8], double out[]) const {
    const HamiltonianParts hp = hamiltonian_parts(self(), y);
    out[0] = 0.5 * hp.two_h;
    self().conserved(y, hp, out, nullptr);
  }

  // A radius no ray passes in this chart, for a spacetime that is not asymptotically flat (inside a
  // cosmological horizon, Schwarzschild-de Sitter): rays escape there, with their direction of motion and
  // no Born tail to infinity (asymptotics.h). 0: asymptotically flat (the trace's escape radius, the tail).
  double escape_limit() const { return 0.0; }

  // Outer horizon radius (0 if none); a ray whose radius drops below it is absorbed.
  double horizon_radius() const { return 0.0; }
  bool absorbed(const double* x) const { return self().radius(x) < self().horizon_radius(); }

  // Rays traced backwards in time (camera rays) cannot cross the future horizon of the ingoing
  // Kerr-Schild chart: they approach it asymptotically while their momentum diverges. They are
  // captured instead when they move inward through a sphere between the horizon and the innermost
  // photon orbit, inside which no inward-moving light ray turns back out.
  double capture_radius() const { return self().horizon_radius(); }

  // Angular velocity d(phi)/dt about +z of a prograde circular (Keplerian) orbit through chart point x,
  // for emitters that orbit (accretion disks); 0 where nothing pulls.
  double keplerian_omega(const double* /*x*/) const { return 0.0; }

  // Length scale of the strong-field region, used by the seed RK4 step halving and drift scales.
  double length_scale() const { return 1.0; }

  // Moves a state to another chart of the same spacetime (Ellis: the other sheet's chart); returns
  // true if it changed the state, so a stepper must re-evaluate its cached derivative.
  bool normalize_chart(double* /*y*/, int& /*sheet*/) const { return false; }

  // Map between the integration chart and the user's Cartesian frame on `sheet`.
  // Returns the sheet the point lies on (a state may sit just past the throat before its chart is
  // normalised).
  int chart_to_user(const double* x, int sheet, double pos[3]) const {
    pos[0] = x[1];
    pos[1] = x[2];
    pos[2] = x[3];
    return sheet;
  }
  std::string outside_chart_message(const double* /*pos*/) const { return "lies outside the metric's chart"; }

  // Returns false if the point lies outside the chart (e.g. inside the Ellis throat radius).
  bool user_to_chart(const double pos[3], int /*sheet*/, double x[4]) const {
    x[0] = 0.0;
    x[1] = pos[0];
    x[2] = pos[1];
    x[3] = pos[2];
    return true;
  }
};

}  // namespace wv
