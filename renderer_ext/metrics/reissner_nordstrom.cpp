// Reissner-Nordstrom spacetime of mass M and electric charge Q (|Q| < M) in Cartesian Kerr-Schild
// (ingoing, horizon-penetrating) coordinates:
//
//   ds^2 = -dt^2 + dx^2 + dy^2 + dz^2 + f (dt + (x dx + y dy + z dz) / r)^2,   f = (2 M r - Q^2) / r^2,
//   g^{mu nu} = eta^{mu nu} - f l^mu l^nu,   l^mu = (-1, x / r),   r = |x| (the areal radius).
//
// Horizons where f = 1: r+- = M +- sqrt(M^2 - Q^2); photon sphere r = (3M + sqrt(9 M^2 - 8 Q^2)) / 2.
// Light does not feel the charge's field, only its energy's gravity. Conserved: E = -p_t, the angular
// momentum L = x cross p (monitored as Lz and L^2), and H = 0. Q = 0 is Schwarzschild.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/simd.h"
#include "engine/register.h"
#include "spacetime/frame.h"
#include "spacetime/metric.h"

namespace wv {

struct ReissnerNordstrom : MetricBase<ReissnerNordstrom> {
  static constexpr const char* kName = "reissner_nordstrom";
  static constexpr const char* kClassName = "ReissnerNordstrom";
  static constexpr const char* kSummary = "Charged, non-rotating black hole (Cartesian Kerr-Schild coordinates)";
  static constexpr ParamSpec kParams[] = {
      {"mass", 0.0, true, kUnbounded, false, 1.0, 1.0, "M > 0"},
      {"charge", -kUnbounded, true, kUnbounded, true, 0.0, 0.8, "electric charge Q in units of length, |Q| < M"}};
  static constexpr int kNumParams = 2;
  static constexpr const char* kParamRelation = "|charge| < mass";
  static std::string param_relation_problem(const double* p) {
    if (std::fabs(p[1]) < p[0]) return {};
    return "|charge| must be < mass (|Q| >= M has no horizon: a naked singularity), got charge " +
           std::to_string(p[1]) + " for mass " + std::to_string(p[0]);
  }
  static constexpr int kNumInvariants = 4;
  static constexpr const char* kInvariantNames[kNumInvariants] = {"H", "E", "Lz", "L2"};
  double M, Q2;

  explicit ReissnerNordstrom(const std::vector<double>& p) : M(p[0]), Q2(p[1] * p[1]) {}

  template <class T>
  void inverse_metric(const T* x, T gi[4][4]) const {
    const T r = sqrt(x[1] * x[1] + x[2] * x[2] + x[3] * x[3]);
    const T f = (2.0 * M * r - Q2) / (r * r);
    const T l[4] = {T(-1.0), x[1] / r, x[2] / r, x[3] / r};
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) gi[a][b] = T(a == b ? (a == 0 ? -1.0 : 1.0) : 0.0) - f * l[a] * l[b];
  }

  // Hand-written Hamilton equations (T is double or Lanes): H = (-p_t^2 + |p|^2) / 2 - (f / 2) L^2 with
  // L = -p_t + x.p / r, so dp_i = (L^2 / 2) d_i f + f L d_i L, d_i f = (2 Q^2 / r^4 - 2 M / r^3) x_i,
  // d_i L = p_i / r - (x.p) x_i / r^3.
  template <class T>
  WV_INLINE void rhs(const T y[8], T dy[8]) const {
    const T x = y[1], yy = y[2], z = y[3], pt = y[4], px = y[5], py = y[6], pz = y[7];
    const T r2 = x * x + yy * yy + z * z, r = sqrt(r2), ir = 1.0 / r, ir2 = ir * ir;
    const T f = (2.0 * M * r - Q2) * ir2;
    const T xp = x * px + yy * py + z * pz;
    const T L = -pt + xp * ir;
    const T fL = f * L;
    dy[0] = -pt + fL;
    dy[1] = px - fL * x * ir;
    dy[2] = py - fL * yy * ir;
    dy[3] = pz - fL * z * ir;
    dy[4] = T{};
    const T ir3 = ir2 * ir;
    const T c = L * L * (Q2 * ir2 * ir2 - M * ir3) - fL * xp * ir3;
    const T d = fL * ir;
    dy[5] = c * x + d * px;
    dy[6] = c * yy + d * py;
    dy[7] = c * z + d * pz;
  }

  // The static observer's frame (r > r+) in closed form, as for every Kerr-Schild metric (spacetime/frame.h).
  bool closed_frame(const double* x, ObserverFrame& fr) const {
    const double r = radius(x);
    if (!(r > 0.0)) return false;
    const double l[3] = {x[1] / r, x[2] / r, x[3] / r};
    return kerr_schild_static_frame((2.0 * M * r - Q2) / (r * r), l, fr);
  }

  double radius(const double* x) const { return std::sqrt(x[1] * x[1] + x[2] * x[2] + x[3] * x[3]); }
  double horizon_radius() const { return M + std::sqrt(std::max(0.0, M * M - Q2)); }
  double photon_sphere_radius() const { return 0.5 * (3.0 * M + std::sqrt(std::max(0.0, 9.0 * M * M - 8.0 * Q2))); }
  // Halfway between the horizon and the photon sphere: no inward light ray turns back out inside it.
  double capture_radius() const { return 0.5 * (horizon_radius() + photon_sphere_radius()); }
  Landmarks landmarks() const {
    Landmarks l = MetricBase::landmarks();
    l.inner_horizon = M - std::sqrt(std::max(0.0, M * M - Q2));
    l.photon_sphere = photon_sphere_radius();
    l.mass = M;
    return l;
  }
  // Circular orbits: Omega^2 = (M r - Q^2) / r^4 (0 where gravity no longer holds an orbit).
  double keplerian_omega(const double* x) const {
    const double r = radius(x);
    return std::sqrt(std::max(0.0, M * r - Q2)) / (r * r);
  }
  double length_scale() const { return M; }

  // Static and spherical: A = 1 - 2M u + Q^2 u^2, h = 1; rays inside the photon sphere's impact parameter
  // fall in.
  static constexpr bool kStaticSpherical = true;
  SphericalLens spherical_lens() const {
    SphericalLens s;
    s.a[1] = -2.0 * M;
    s.a[2] = Q2;
    s.u_inner = 1.0 / photon_sphere_radius();
    return s;
  }

  void conserved(const double y[8], const HamiltonianParts& /*hp*/, double out[], double mag[]) const {
    spherical_conserved(y, out, mag);
  }
  void invariant_scales(const double y[8], const double inv[], double scale[]) const {
    spherical_scales(y, inv, M, scale);
  }
};

WARPVIZ_REGISTER_METRIC(ReissnerNordstrom);

}  // namespace wv
