// Ellis (Ellis-Bronnikov) wormhole with throat radius b0:
//
//   ds^2 = -dt^2 + dl^2 + (b0^2 + l^2) dOmega^2,   -inf < l < inf,
//
// integrated in the chart that is regular at the throat: l = (rho - b0^2 / rho) / 2 makes it
// conformally flat,  ds^2 = -dt^2 + Omega(rho)^2 (dx^2 + dy^2 + dz^2),  Omega = (1 + b0^2 / rho^2) / 2,
// rho = |x|, with rho > b0 our sheet and rho < b0 the other. The inversion x -> b0^2 x / rho^2 is an
// isometry exchanging the sheets, so a ray is always kept at rho >= b0 with a sheet flag: when a step
// ends inside rho < b0 the state is inverted and the flag flipped (normalize_chart). The user sees each
// sheet as its own Cartesian frame with |x| = sqrt(b0^2 + l^2) = rho Omega, the areal radius.
// Conserved: E = -p_t, L = x cross p (monitored as L^2, the angular invariant), and H = 0.
#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "engine/register.h"
#include "core/simd.h"
#include "spacetime/frame.h"
#include "spacetime/metric.h"
#include "spacetime/throat_chart.h"

namespace wv {

struct EllisWormhole : MetricBase<EllisWormhole> {
  static constexpr const char* kName = "ellis";
  static constexpr const char* kClassName = "EllisWormhole";
  static constexpr const char* kSummary = "Ellis wormhole joining two asymptotically flat sheets";
  static constexpr ParamSpec kParams[] = {{"throat", 0.0, true, kUnbounded, false, 1.0, 1.0, "throat radius b0 > 0"}};
  static constexpr int kNumParams = 1;
  static constexpr int kSheets = 2;
  static constexpr int kNumInvariants = 3;
  static constexpr bool kUserIsChart = false;
  static constexpr const char* kInvariantNames[kNumInvariants] = {"H", "E", "L2"};
  double b0, b02;

  explicit EllisWormhole(const std::vector<double>& p)
      : b0(p[0]), b02(b0 * b0) {}

  Landmarks landmarks() const {
    Landmarks l;
    l.throat = b0;
    l.mass = b0;
    return l;
  }

  template <class T>
  void inverse_metric(const T* x, T gi[4][4]) const {
    const T rho2 = x[1] * x[1] + x[2] * x[2] + x[3] * x[3];
    const T om = 0.5 * (1.0 + b02 / rho2);
    const T inv_om2 = 1.0 / (om * om);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) gi[a][b] = T(0.0);
    gi[0][0] = T(-1.0);
    gi[1][1] = gi[2][2] = gi[3][3] = inv_om2;
  }

  // The static observer's frame in closed form: g = diag(-1, Omega^2, Omega^2, Omega^2), u = d_t, e_j = d_j / Omega.
  bool closed_frame(const double* x, ObserverFrame& fr) const {
    const double rho2 = x[1] * x[1] + x[2] * x[2] + x[3] * x[3];
    const double om = 0.5 * (1.0 + b02 / rho2);
    if (!(rho2 > 0.0) || !std::isfinite(om * om)) return false;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) fr.g[a][b] = a != b ? 0.0 : (a == 0 ? -1.0 : om * om);
    fr.u[0] = 1.0;
    fr.u[1] = fr.u[2] = fr.u[3] = 0.0;
    for (int j = 0; j < 3; ++j)
      for (int mu = 0; mu < 4; ++mu) fr.e[j][mu] = mu == j + 1 ? 1.0 / om : 0.0;
    return true;
  }

  // H = (-p_t^2 + |p|^2 / Omega^2) / 2;  d_i Omega = -b0^2 x_i / rho^4.
  // T is double or Lanes (core/simd.h).
  template <class T>
  WV_INLINE void rhs(const T y[8], T dy[8]) const {
    const T x = y[1], yy = y[2], z = y[3], px = y[5], py = y[6], pz = y[7];
    const T rho2 = x * x + yy * yy + z * z;
    const T om = 0.5 * (1.0 + b02 / rho2), iom = 1.0 / om, iom2 = iom * iom;
    const T p2 = px * px + py * py + pz * pz;
    dy[0] = -y[4];
    dy[1] = px * iom2;
    dy[2] = py * iom2;
    dy[3] = pz * iom2;
    dy[4] = T{};
    const T c = -p2 * b02 * iom2 * iom / (rho2 * rho2);
    dy[5] = c * x;
    dy[6] = c * yy;
    dy[7] = c * z;
  }

  double radius(const double* x) const {
    const double rho2 = x[1] * x[1] + x[2] * x[2] + x[3] * x[3], rho = std::sqrt(rho2);
    return 0.5 * (rho + b02 / rho);
  }
  double length_scale() const { return b0; }

  // Static and spherical in the areal radius R = sqrt(b0^2 + l^2): A = 1, h = 1 - b0^2 u^2 (dl^2 =
  // dR^2 / h); rays below impact parameter b0 pass through the throat to the other sheet.
  static constexpr bool kStaticSpherical = true;
  SphericalLens spherical_lens() const {
    SphericalLens s;
    s.h[2] = -b02;
    s.u_inner = 1.0 / b0;
    s.throat = true;
    return s;
  }

  bool normalize_chart(double* y, int& sheet) const { return invert_through_throat(y, b02, sheet); }

  int chart_to_user(const double* x, int sheet, double pos[3]) const {
    const double rho2 = x[1] * x[1] + x[2] * x[2] + x[3] * x[3];
    const double scale = 0.5 * (1.0 + b02 / rho2);  // areal radius / rho
    for (int i = 0; i < 3; ++i) pos[i] = x[1 + i] * scale;
    return rho2 >= b02 ? sheet : -sheet;
  }
  bool user_to_chart(const double pos[3], int /*sheet*/, double x[4]) const {
    const double R = std::sqrt(pos[0] * pos[0] + pos[1] * pos[1] + pos[2] * pos[2]);
    if (!(R >= b0)) return false;
    const double rho = R + std::sqrt(std::max(0.0, (R - b0) * (R + b0)));
    x[0] = 0.0;
    for (int i = 0; i < 3; ++i) x[1 + i] = pos[i] * rho / R;
    return true;
  }
  std::string outside_chart_message(const double* pos) const {
    std::ostringstream s;
    s << "lies inside the wormhole throat (|x| = "
      << std::sqrt(pos[0] * pos[0] + pos[1] * pos[1] + pos[2] * pos[2]) << " < throat = " << b0
      << "; positions are areal radii, which are at least the throat)";
    return s.str();
  }

  void conserved(const double y[8], const HamiltonianParts& /*hp*/, double out[], double mag[]) const {
    double l[3];
    angular_momentum(y, l);
    out[1] = -y[4];
    out[2] = l[0] * l[0] + l[1] * l[1] + l[2] * l[2];
    if (mag) {
      mag[1] = std::fabs(y[4]);
      mag[2] = (y[1] * y[1] + y[2] * y[2] + y[3] * y[3]) * (y[5] * y[5] + y[6] * y[6] + y[7] * y[7]);
    }
  }
  void invariant_scales(const double y[8], const double inv[], double scale[]) const {
    scale[0] = 1.0;
    scale[1] = energy_scale(y, inv[1]);
    scale[2] = std::max(inv[2], b02 * scale[1] * scale[1]);
  }
};

WARPVIZ_REGISTER_METRIC(EllisWormhole);

}  // namespace wv
