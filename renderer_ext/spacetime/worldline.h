// An observer's worldline: a timelike geodesic, integrated by the same Hamiltonian and stepper as light
// (H = 1/2 g^{mu nu} p_mu p_nu is -1/2 along it, p_mu = u_mu, the parameter its proper time), sampled at
// given proper times. A film's camera moves along one (warpviz/film/paths.py).
#pragma once

#include <algorithm>
#include <cmath>

#include "spacetime/steppers/dop853.h"

namespace wv {

struct WorldlinePoint {
  double x[4];    // chart point
  double u[4];    // 4-velocity u^mu (chart components)
  double pos[3];  // user-frame position
  int sheet = 1;
};

// Integrates the geodesic from chart point x0 with 4-velocity u0 (u^mu) on `sheet` to each proper time
// taus[0..n) (ascending, >= 0) with dop853 at tolerance tol, writing out[i]; stops early where the radius
// falls below stop_radius, the state stops being finite, or the metric cannot go on. Returns the number of
// points written.
template <class M>
int worldline(const M& m, const double x0[4], const double u0[4], int sheet, const double* taus, int n,
              double stop_radius, double tol, WorldlinePoint* out) {
  double y[8], gi[4][4], g[4][4];
  m.inverse_metric(x0, gi);
  if (!invert4(gi, g)) return 0;
  for (int a = 0; a < 4; ++a) {
    y[a] = x0[a];
    y[4 + a] = 0.0;
    for (int b = 0; b < 4; ++b) y[4 + a] += g[a][b] * u0[b];  // p_mu = u_mu
  }
  Dop853<M> st;
  st.init(m, y);
  double tau = 0.0, ynew[8];
  double h = 1e-2 * std::max(1.0, m.radius(y));
  auto write = [&](int i) {
    WorldlinePoint& p = out[i];
    double dy[8];
    m.rhs(y, dy);
    for (int a = 0; a < 4; ++a) {
      p.x[a] = y[a];
      p.u[a] = dy[a];  // dx^mu / dtau = g^{mu nu} p_nu
    }
    p.sheet = m.chart_to_user(y, sheet, p.pos);
  };
  long attempts = 0;
  for (int i = 0; i < n; ++i) {
    while (tau < taus[i]) {
      if (++attempts > 10000000) return i;
      const double step = std::min(h, taus[i] - tau);
      const double err = st.attempt(m, y, step, tol, ynew);
      if (!(err <= 1.0)) {
        h = step * std::max(0.2, 0.9 * std::pow(std::max(err, 1e-300), -1.0 / 8.0));
        if (!(h > 1e-14 * (1.0 + tau))) return i;
        continue;
      }
      for (int k = 0; k < 8; ++k) y[k] = ynew[k];
      st.accept();
      tau = step == taus[i] - tau ? taus[i] : tau + step;
      if (m.normalize_chart(y, sheet)) st.init(m, y);  // a wormhole's other sheet: the state's chart changed
      for (int k = 0; k < 8; ++k)
        if (!std::isfinite(y[k])) return i;
      if (m.radius(y) < stop_radius) return i;
      h = step * std::min(5.0, 0.9 * std::pow(std::max(err, 1e-300), -1.0 / 8.0));
    }
    write(i);
  }
  return n;
}

}  // namespace wv
