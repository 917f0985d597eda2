// Schwarzschild spacetime of mass M in Cartesian Kerr-Schild (ingoing, horizon-penetrating) coordinates:
//
//   ds^2 = -dt^2 + dx^2 + dy^2 + dz^2 + (2M / r) (dt + (x dx + y dy + z dz) / r)^2,   r = |x|,
//   g^{mu nu} = eta^{mu nu} - (2M / r) l^mu l^nu,   l^mu = (-1, x / r).
//
// Horizon r = 2M; photon sphere r = 3M. Conserved: E = -p_t, the angular momentum vector
// L = x cross p (monitored as Lz and L^2 = |L|^2), and H = 0.
#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/register.h"
#include "core/simd.h"
#include "spacetime/frame.h"
#include "spacetime/metric.h"

namespace wv {

struct Schwarzschild : MetricBase<Schwarzschild> {
  static constexpr const char* kName = "schwarzschild";
  static constexpr const char* kClassName = "Schwarzschild";
  static constexpr const char* kSummary = "Non-rotating black hole (Cartesian Kerr-Schild coordinates)";
  static constexpr ParamSpec kParams[] = {{"mass", 0.0, true, kUnbounded, false, 1.0, 1.0, "M > 0: horizon 2M, photon sphere 3M"}};
  static constexpr int kNumParams = 1;
  static constexpr int kNumInvariants = 4;
  static constexpr const char* kInvariantNames[kNumInvariants] = {"H", "E", "Lz", "L2"};
  double M;

  explicit Schwarzschild(const std::vector<double>& p) : M(p[0]) {}

  template <class T>
  void inverse_metric(const T* x, T gi[4][4]) const {
    const T r = sqrt(x[1] * x[1] + x[2] * x[2] + x[3] * x[3]);
    const T f = 2.0 * M / r;
    const T l[4] = {T(-1.0), x[1] / r, x[2] / r, x[3] / r};
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) gi[a][b] = T(a == b ? (a == 0 ? -1.0 : 1.0) : 0.0) - f * l[a] * l[b];
  }

  // Hand-written Hamilton equations, H = (-p_t^2 + |p|^2) / 2 - (f / 2) L^2 with L = -p_t + x.p / r.
  // T is double or Lanes (one ray per lane, core/simd.h).
  template <class T>
  WV_INLINE void rhs(const T y[8], T dy[8]) const {
    const T x = y[1], yy = y[2], z = y[3], pt = y[4], px = y[5], py = y[6], pz = y[7];
    const T r2 = x * x + yy * yy + z * z, r = sqrt(r2), ir = 1.0 / r;
    const T f = 2.0 * M * ir;
    const T xp = x * px + yy * py + z * pz;
    const T L = -pt + xp * ir;
    const T fL = f * L;
    dy[0] = -pt + fL;
    dy[1] = px - fL * x * ir;
    dy[2] = py - fL * yy * ir;
    dy[3] = pz - fL * z * ir;
    dy[4] = T{};
    // dp_i = (L^2 / 2) d_i f + f L d_i L,  d_i f = -2M x_i / r^3,  d_i L = p_i / r - (x.p) x_i / r^3
    const T ir3 = ir * ir * ir;
    const T c = -M * L * L * ir3 - fL * xp * ir3;
    const T d = fL * ir;
    dy[5] = c * x + d * px;
    dy[6] = c * yy + d * py;
    dy[7] = c * z + d * pz;
  }

  // The static observer's frame (r > 2M) in closed form (spacetime/frame.h), l = x / r.
  bool closed_frame(const double* x, ObserverFrame& fr) const {
    const double r = radius(x);
    if (!(r > 0.0)) return false;
    const double l[3] = {x[1] / r, x[2] / r, x[3] / r};
    return kerr_schild_static_frame(2.0 * M / r, l, fr);
  }

  double radius(const double* x) const { return std::sqrt(x[1] * x[1] + x[2] * x[2] + x[3] * x[3]); }
  double horizon_radius() const { return 2.0 * M; }
  double capture_radius() const { return 2.5 * M; }  // between the horizon and the photon sphere (3M)
  Landmarks landmarks() const {
    Landmarks l = MetricBase::landmarks();
    l.photon_sphere = 3.0 * M;
    l.mass = M;
    return l;
  }
  double keplerian_omega(const double* x) const {
    const double r = radius(x);
    return std::sqrt(M / (r * r * r));
  }
  double length_scale() const { return M; }

  // Static and spherical: A = 1 - 2M u, h = 1, rays below the photon sphere's impact parameter fall in.
  static constexpr bool kStaticSpherical = true;
  SphericalLens spherical_lens() const { return SphericalLens::schwarzschild(M); }

  void conserved(const double y[8], const HamiltonianParts& /*hp*/, double out[], double mag[]) const {
    spherical_conserved(y, out, mag);
  }
  void invariant_scales(const double y[8], const double inv[], double scale[]) const {
    spherical_scales(y, inv, M, scale);
  }
};

WARPVIZ_REGISTER_METRIC(Schwarzschild);

}  // namespace wv
