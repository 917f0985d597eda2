// Local observer frames: turning a direction seen by an observer into a covariant photon momentum,
// and back.
//
// The observer is static (4-velocity along the Killing field d/dt) wherever g_tt < 0, and the
// zero-angular-momentum observer (ZAMO, rotating with Omega = -g_tphi / g_phiphi about z) inside an
// ergoregion. Its spatial triad is the Lowdin (symmetric) orthonormalisation of the coordinate axes
// d/dx, d/dy, d/dz projected orthogonal to the 4-velocity: of all orthonormal triads it is the one
// closest to the Cartesian axes, and it rotates with the coordinates, so radial and tangential
// directions of a spherically symmetric metric stay radial and tangential.
#pragma once

#include <cmath>
#include <concepts>

#include "core/linalg.h"

namespace wv {

struct ObserverFrame {
  double g[4][4];  // covariant metric g_{mu nu} at the point
  double u[4];     // observer 4-velocity u^mu
  double e[3][4];  // spatial triad e_j^mu, j = x, y, z
};

// The zero-angular-momentum observer's 4-velocity u^mu at chart point x in the metric g_{mu nu}: it rotates
// about z with Omega = -g_tphi / g_phiphi (on the axis, where g_phiphi = 0, it is at rest); false where that
// motion is not timelike (inside a horizon).
inline bool zamo_velocity(const double g[4][4], const double x[4], double u[4]) {
  const double xi[4] = {0.0, -x[2], x[1], 0.0};  // rotation about z
  double gtp = 0.0, gpp = 0.0;
  for (int i = 1; i < 4; ++i) {
    gtp += g[0][i] * xi[i];
    for (int j = 1; j < 4; ++j) gpp += g[i][j] * xi[i] * xi[j];
  }
  const double om = gpp > 0.0 ? -gtp / gpp : 0.0;
  const double v[4] = {1.0, om * xi[1], om * xi[2], 0.0};
  double n2 = 0.0;
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) n2 += g[a][b] * v[a] * v[b];
  if (!(n2 < 0.0)) return false;
  const double s = 1.0 / std::sqrt(-n2);
  for (int a = 0; a < 4; ++a) u[a] = v[a] * s;
  return true;
}

// The observer's 4-velocity u^mu (and the covariant metric g_{mu nu}) at x; false where no static
// observer or ZAMO exists (inside a horizon) or the metric is singular.
template <class M>
bool observer_velocity(const M& m, const double x[4], double g[4][4], double u[4]) {
  double gi[4][4];
  m.inverse_metric(x, gi);
  if (!invert4(gi, g)) return false;
  if (g[0][0] < 0.0) {
    u[0] = 1.0 / std::sqrt(-g[0][0]);
    u[1] = u[2] = u[3] = 0.0;
    return true;
  }
  return zamo_velocity(g, x, u);
}

// A metric may give its observer frame in closed form,
//   bool closed_frame(const double x[4], ObserverFrame& f) const;
// the same frame as the generic construction below (tests/test_metric_contract.py compares them),
// at a fraction of its cost: frames are built at every path vertex.
template <class M>
concept HasClosedFrame = requires(const M& m, const double* x, ObserverFrame& f) {
  { m.closed_frame(x, f) } -> std::same_as<bool>;
};

// The static observer's frame of a Kerr-Schild metric g = eta + f l (x) l, l_mu = (1, l), |l| = 1, where
// f < 1: u = d_t / sqrt(1 - f), and since the projected axes' Gram matrix is I + l l^T f / (1 - f), whose
// inverse square root is I + (sqrt(1 - f) - 1) l l^T, the Lowdin triad is
// e_j = f l_j / sqrt(1 - f) d_t + (delta_kj + (sqrt(1 - f) - 1) l_k l_j) d_k. False where f >= 1.
inline bool kerr_schild_static_frame(double f, const double l[3], ObserverFrame& fr) {
  if (!(f < 1.0)) return false;
  const double s = std::sqrt(1.0 - f), c = s - 1.0;
  fr.g[0][0] = f - 1.0;
  for (int i = 0; i < 3; ++i) {
    fr.g[0][i + 1] = fr.g[i + 1][0] = f * l[i];
    for (int j = 0; j < 3; ++j) fr.g[i + 1][j + 1] = (i == j ? 1.0 : 0.0) + f * l[i] * l[j];
  }
  fr.u[0] = 1.0 / s;
  fr.u[1] = fr.u[2] = fr.u[3] = 0.0;
  for (int j = 0; j < 3; ++j) {
    fr.e[j][0] = f * l[j] / s;
    for (int k = 0; k < 3; ++k) fr.e[j][k + 1] = (j == k ? 1.0 : 0.0) + c * l[k] * l[j];
  }
  return true;
}

// The spatial triad f.e of the observer f.u in the metric f.g: the Lowdin (symmetric) orthonormalisation of
// the coordinate axes d/dx, d/dy, d/dz projected orthogonal to f.u. For the local observer it is its frame;
// for any other 4-velocity (a moving camera, spacetime/observers.h) it is, in flat space, the static
// frame's axes boosted to that velocity. False where the projected axes are degenerate.
inline bool lowdin_triad(ObserverFrame& f) {
  const auto& g = f.g;
  double ul[4];  // u lowered: g(d_mu, u)
  for (int a = 0; a < 4; ++a) {
    ul[a] = 0.0;
    for (int b = 0; b < 4; ++b) ul[a] += g[a][b] * f.u[b];
  }
  // Projected axes b_i = d_i + g(d_i, u) u have Gram matrix G_ij = g_ij + u_i u_j.
  double gram[3][3], s[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) gram[i][j] = g[i + 1][j + 1] + ul[i + 1] * ul[j + 1];
  if (!sym_inv_sqrt3(gram, s)) return false;
  for (int j = 0; j < 3; ++j)
    for (int mu = 0; mu < 4; ++mu) {
      double acc = 0.0;
      for (int i = 0; i < 3; ++i) {
        const double bmu = (mu == i + 1 ? 1.0 : 0.0) + ul[i + 1] * f.u[mu];
        acc += bmu * s[i][j];
      }
      f.e[j][mu] = acc;
    }
  return true;
}

// Returns false where no static observer or ZAMO exists (inside a horizon) or the metric is singular.
template <class M>
bool observer_frame_generic(const M& m, const double x[4], ObserverFrame& f) {
  if (!observer_velocity(m, x, f.g, f.u)) return false;
  return lowdin_triad(f);
}

template <class M>
bool observer_frame(const M& m, const double x[4], ObserverFrame& f) {
  if constexpr (HasClosedFrame<M>)
    return m.closed_frame(x, f);
  else
    return observer_frame_generic(m, x, f);
}

// Photon energy |p . u| measured by the local static observer (ZAMO in an ergoregion) at state y;
// 0 where no such observer exists (on or inside a horizon).
template <class M>
double local_energy(const M& m, const double y[8]) {
  double g[4][4], u[4];
  if (!observer_velocity(m, y, g, u)) return 0.0;
  double e = 0.0;
  for (int mu = 0; mu < 4; ++mu) e += y[4 + mu] * u[mu];
  return std::fabs(e);
}

// Covariant momentum p_mu of a photon of unit local energy moving along the unit vector n of the frame.
inline void frame_to_momentum(const ObserverFrame& f, const double n[3], double p[4]) {
  double pu[4];
  for (int mu = 0; mu < 4; ++mu) pu[mu] = f.u[mu] + n[0] * f.e[0][mu] + n[1] * f.e[1][mu] + n[2] * f.e[2][mu];
  for (int a = 0; a < 4; ++a) {
    p[a] = 0.0;
    for (int b = 0; b < 4; ++b) p[a] += f.g[a][b] * pu[b];
  }
}

// State y = (chart position, covariant momentum) of a photon of unit local energy leaving user-frame
// point pos on `sheet` along the local observer's unit direction dir; false outside the chart or where no
// observer exists.
template <class M>
bool photon_state(const M& m, const double pos[3], const double dir[3], int sheet, double y[8]) {
  ObserverFrame f;
  if (!m.user_to_chart(pos, sheet, y) || !observer_frame(m, y, f)) return false;
  frame_to_momentum(f, dir, y + 4);
  return true;
}

// Unit direction n seen by the frame's observer for covariant momentum p; returns the local energy.
inline double momentum_to_frame(const ObserverFrame& f, const double p[4], double n[3]) {
  double energy = 0.0;
  for (int mu = 0; mu < 4; ++mu) energy -= p[mu] * f.u[mu];
  double norm2 = 0.0;
  for (int j = 0; j < 3; ++j) {
    n[j] = 0.0;
    for (int mu = 0; mu < 4; ++mu) n[j] += p[mu] * f.e[j][mu];
    norm2 += n[j] * n[j];
  }
  const double inv = norm2 > 0.0 ? 1.0 / std::sqrt(norm2) : 0.0;
  for (int j = 0; j < 3; ++j) n[j] *= inv;
  return energy;
}

}  // namespace wv
