// Kerr spacetime of mass M and spin a = spin * M (angular momentum along +z) in Cartesian Kerr-Schild
// (ingoing, horizon-penetrating) coordinates:
//
//   ds^2 = -dt^2 + dx^2 + dy^2 + dz^2 + f (l_mu dx^mu)^2,
//   f = 2 M r^3 / (r^4 + a^2 z^2),   l_mu = (1, (r x + a y) / (r^2 + a^2), (r y - a x) / (r^2 + a^2), z / r),
//   x^2 + y^2 + z^2 = r^2 + a^2 - a^2 z^2 / r^2   (r is the Boyer-Lindquist radius),
//   g^{mu nu} = eta^{mu nu} - f l^mu l^nu.
//
// Outer horizon r+ = M + sqrt(M^2 - a^2); static observers exist outside the ergosurface
// r = M + sqrt(M^2 - a^2 cos^2 theta), ZAMOs down to r+. Conserved: E = -p_t, Lz = x p_y - y p_x,
// Carter's Q = p_theta^2 + cos^2 theta (Lz^2 / sin^2 theta - a^2 E^2) (null rays), written below in a
// form regular on the axis, and H = 0.
#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/register.h"
#include "core/simd.h"
#include "spacetime/frame.h"
#include "spacetime/kerr_shadow.h"
#include "spacetime/metric.h"

namespace wv {

struct Kerr : MetricBase<Kerr> {
  static constexpr const char* kName = "kerr";
  static constexpr const char* kClassName = "Kerr";
  static constexpr const char* kSummary = "Rotating black hole (Cartesian Kerr-Schild coordinates, spin along +z)";
  static constexpr ParamSpec kParams[] = {
      {"mass", 0.0, true, kUnbounded, false, 1.0, 1.0, "M > 0"},
      {"spin", -1.0, true, 1.0, true, 0.0, 0.9, "a/M, |spin| < 1 (|a/M| >= 1 has no horizon); negative spins rotate about -z"}};
  static constexpr int kNumParams = 2;
  static constexpr int kNumInvariants = 4;
  static constexpr const char* kInvariantNames[kNumInvariants] = {"H", "E", "Lz", "Q"};
  double M, a, r_plus;

  explicit Kerr(const std::vector<double>& p)
      : M(p[0]),
        a(p[1] * p[0]),
        r_plus(M + std::sqrt((M - a) * (M + a))) {}

  // Boyer-Lindquist r from Cartesian Kerr-Schild x, y, z; stable on both sides of the disk r = 0.
  // T is double, Dual<4> or Lanes (core/simd.h).
  template <class T>
  WV_INLINE T bl_radius(const T& x, const T& y, const T& z) const {
    const T w = x * x + y * y + z * z - a * a;
    const T disc = sqrt(w * w + 4.0 * a * a * z * z);
    const T r2 = (w < 0.0) ? (2.0 * a * a) * z * z / (disc - w) : 0.5 * (w + disc);
    return sqrt(r2);
  }

  template <class T>
  void inverse_metric(const T* x, T gi[4][4]) const {
    const T r = bl_radius(x[1], x[2], x[3]);
    const T s = r * r + a * a;
    const T f = 2.0 * M * r * r * r / (r * r * r * r + a * a * x[3] * x[3]);
    const T l[4] = {T(-1.0), (r * x[1] + a * x[2]) / s, (r * x[2] - a * x[1]) / s, x[3] / r};
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) gi[i][j] = T(i == j ? (i == 0 ? -1.0 : 1.0) : 0.0) - f * l[i] * l[j];
  }

  // Hand-written Hamilton equations. H = (-p_t^2 + |p|^2) / 2 - (f / 2) L^2, L = l^mu p_mu, and
  // d_i r = (x r^3, y r^3, z r (r^2 + a^2)) / (r^4 + a^2 z^2) from differentiating the r-equation.
  template <class T>
  WV_INLINE void rhs(const T y[8], T dy[8]) const {
    const T x = y[1], yy = y[2], z = y[3], pt = y[4], px = y[5], py = y[6], pz = y[7];
    const T r = bl_radius(x, yy, z);
    const double a2 = a * a;
    const T r2 = r * r, r3 = r2 * r, z2 = z * z;
    const T s = r2 + a2, is = 1.0 / s, ir = 1.0 / r;
    const T q = r2 * r2 + a2 * z2, iq = 1.0 / q;
    const T f = 2.0 * M * r3 * iq;
    const T lx = (r * x + a * yy) * is, ly = (r * yy - a * x) * is, lz = z * ir;
    const T L = -pt + lx * px + ly * py + lz * pz;
    const T fL = f * L;
    dy[0] = -pt + fL;
    dy[1] = px - fL * lx;
    dy[2] = py - fL * ly;
    dy[3] = pz - fL * lz;
    dy[4] = T{};
    // derivatives of r
    const T dr_x = x * r3 * iq, dr_y = yy * r3 * iq, dr_z = z * r * s * iq;
    // f = f(r, z): partials at fixed z and at fixed r
    const T f_r = 2.0 * M * r2 * (3.0 * a2 * z2 - r2 * r2) * iq * iq;
    const T f_z = -4.0 * M * a2 * r3 * z * iq * iq;
    // L = L(x, y, z, r): explicit partials and the partial in r
    const T A = x * px + yy * py, B = yy * px - x * py;
    const T L_r = A * is - 2.0 * r * (r * A + a * B) * is * is - z * pz * ir * ir;
    const T L_x = (r * px - a * py) * is, L_y = (r * py + a * px) * is, L_z = pz * ir;
    const T hL2 = 0.5 * L * L;
    dy[5] = hL2 * f_r * dr_x + fL * (L_x + L_r * dr_x);
    dy[6] = hL2 * f_r * dr_y + fL * (L_y + L_r * dr_y);
    dy[7] = hL2 * (f_r * dr_z + f_z) + fL * (L_z + L_r * dr_z);
  }

  // The static observer's frame in closed form (spacetime/frame.h) outside the ergosurface, where f < 1;
  // the generic construction (the ZAMO) inside it.
  bool closed_frame(const double* x, ObserverFrame& fr) const {
    const double r = radius(x), s = r * r + a * a;
    const double f = 2.0 * M * r * r * r / (r * r * r * r + a * a * x[3] * x[3]);
    const double l[3] = {(r * x[1] + a * x[2]) / s, (r * x[2] - a * x[1]) / s, x[3] / r};
    if (r > 0.0 && std::isfinite(f) && kerr_schild_static_frame(f, l, fr)) return true;
    return observer_frame_generic(*this, x, fr);
  }

  double radius(const double* x) const { return bl_radius(x[1], x[2], x[3]); }
  // The Schwarzschild lens map of the same mass: the light connection's proposal (integrators/lens_proposal.h)
  // and where the image proxies start their Newton search (integrators/light_connection.h).
  static constexpr bool kLensProxy = true;
  SphericalLens lens_proxy() const { return SphericalLens::schwarzschild(M); }
  // Twice the spin length a, the largest shift of Kerr's shadow from Schwarzschild's: frame dragging moves Kerr's
  // images of a light point off the proxy's by about that much at the light. In the Kerr rooms (a/M = 0.6, 0.9,
  // 0.99, a 30-unit lamp, 48 x 36 x 16 spp) the error was lowest for margins drawn by area of 0.05-0.1, 0.1 and
  // >= 0.1 of the lamp's size (a = 0.056, 0.104 and 0.145 of it), and with the margin's share of the draws cut to
  // 0.15 (lens_proposal.h, kProposalMarginShare), for 2a in fig10d (benchmarks/README.md).
  double lens_proxy_margin() const { return 2.0 * std::fabs(a); }
  // The proposal's proxy masses (integrators/lens_proposal.h, ProxyMass): for light whose angular momentum makes
  // cosine c with the spin (the direction of lens_proxy_spin), the Schwarzschild mass b_c / sqrt(27) whose critical
  // impact parameter is Kerr's b_c at that inclination (spacetime/kerr_shadow.h).
  V3 lens_proxy_spin() const { return {0.0, 0.0, a}; }
  double lens_proxy_mass(double c) const { return kerr_critical_mass(M, a, c); }
  double horizon_radius() const { return r_plus; }
  // Halfway between the horizon and the prograde equatorial photon orbit (the innermost one).
  double capture_radius() const { return r_plus + 0.5 * (photon_orbit(-1.0) - r_plus); }
  // Equatorial circular photon orbit, prograde (sense -1) or retrograde (+1) (Bardeen, Press & Teukolsky).
  double photon_orbit(double sense) const { return kerr_photon_orbit(M, a, sense); }
  // The spherical photon orbit with zero angular momentum, over the poles: the largest root of
  // r^3 - 3 M r^2 + a^2 r + a^2 M = 0.
  double polar_photon_orbit() const {
    const double s = std::sqrt(M * M - a * a / 3.0);
    return M + 2.0 * s * std::cos(std::acos(std::min(1.0, M * (M * M - a * a) / (s * s * s))) / 3.0);
  }
  Landmarks landmarks() const {
    Landmarks l = MetricBase::landmarks();
    l.inner_horizon = M - std::sqrt((M - a) * (M + a));
    if (std::fabs(a) <= 1e-12 * M) {  // the photon region's walls have merged into the sphere r = 3M
      l.photon_sphere = 3.0 * M;
    } else {
      l.photon_prograde = photon_orbit(-1.0);
      l.photon_retrograde = photon_orbit(1.0);
      l.photon_polar = polar_photon_orbit();
    }
    if (a != 0.0) l.ergosphere = 2.0 * M;
    l.mass = M;
    l.spin = a;
    return l;
  }
  // Prograde equatorial circular orbit (Bardeen, Press & Teukolsky): Omega = sqrt(M) / (r^1.5 + a sqrt(M)).
  double keplerian_omega(const double* x) const {
    const double r = radius(x), sm = std::sqrt(M);
    return sm / (r * std::sqrt(r) + a * sm);
  }
  double length_scale() const { return M; }

  void conserved(const double y[8], const HamiltonianParts& hp, double out[], double mag[]) const {
    const double x = y[1], yy = y[2], z = y[3], px = y[5], py = y[6], pz = y[7];
    const double r = bl_radius(x, yy, z);
    const double E = -y[4];
    const double c = z / r;                                // cos(theta)
    const double s2 = (x * x + yy * yy) / (r * r + a * a);  // sin^2(theta), no cancellation near the axis
    out[1] = E;
    out[2] = x * py - yy * px;
    // p_theta^2 + cot^2(theta) Lz^2, with x^2 + y^2 = (r^2 + a^2) sin^2(theta), regular on the axis
    const double ptheta2_lz = c * c * (r * r + a * a) * (px * px + py * py) - 2.0 * r * c * (x * px + yy * py) * pz +
                              r * r * s2 * pz * pz;
    // Carter's constant for any mass mu^2 = -2H (0 on null rays), so it is exactly conserved by the flow.
    const double mu2 = -hp.two_h;
    out[3] = ptheta2_lz + a * a * c * c * (mu2 - E * E);
    if (mag) {
      mag[1] = std::fabs(E);
      mag[2] = std::fabs(x * py) + std::fabs(yy * px);
      mag[3] = c * c * (r * r + a * a) * (px * px + py * py) + std::fabs(2.0 * r * c * (x * px + yy * py) * pz) +
               r * r * s2 * pz * pz + a * a * c * c * (hp.mag + E * E);
    }
  }
  void invariant_scales(const double y[8], const double inv[], double scale[]) const {
    scale[0] = 1.0;
    scale[1] = energy_scale(y, inv[1]);
    scale[2] = std::max(std::fabs(inv[2]), M * scale[1]);
    scale[3] = std::max(std::fabs(inv[3]), M * M * scale[1] * scale[1]);
  }
};

WARPVIZ_REGISTER_METRIC(Kerr);

}  // namespace wv
