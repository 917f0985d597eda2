// Chart geometry along a light path: maps between user-frame displacements and normals, the metric's chart
// and the local observer frame (with the chart's Jacobian where the chart is not the user frame), and the
// start state of a backward ray, with the start frames a path keeps for the segments leaving one point.
#pragma once

#include <algorithm>
#include <cmath>
#include <type_traits>

#include <vector>

#include "core/vec3.h"
#include "scene/light.h"
#include "scene/scene.h"
#include "spacetime/frame.h"

namespace wv {

// The chart point and observer frame where segments start, kept for the next segments from the same
// point: every segment leaving one side of a vertex (bounce, light connection, pilots) starts at the
// same offset point, and every camera ray at the camera.
struct StartFrames {
  struct Entry {
    V3 pos;
    int sheet = 0;
    bool ok = false;  // the point is in the chart, outside the horizon, with an observer
    double x4[4];
    ObserverFrame f;
  };
  static constexpr int kSize = 2;
  Entry e[kSize];
  int n = 0, next = 0;
};

struct NoFrames {};  // flat space starts every segment without an observer frame
template <class M>
using PathFrames = std::conditional_t<M::kFlat, NoFrames, StartFrames>;

template <class M>
class ChartGeometry {
 public:
  explicit ChartGeometry(const M& m) : m_(m) {}

  // Map from a user-frame displacement at chart point x4 to the local observer frame: q_a = g(e_a, v),
  // v the chart vector of the displacement.
  LinearMap local_map(const double* x4, const ObserverFrame& f) const {
    double jinv[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    if constexpr (!M::kUserIsChart) chart_jacobian_inverse(x4, jinv);
    LinearMap L;
    for (int a = 0; a < 3; ++a)
      for (int j = 0; j < 3; ++j) {
        double acc = 0.0;
        for (int mu = 0; mu < 4; ++mu)
          for (int nu = 1; nu < 4; ++nu) acc += f.e[a][mu] * f.g[mu][nu] * jinv[nu - 1][j];
        L.m[a][j] = acc;
      }
    return L;
  }

  // Local-frame unit normal of a surface with user-frame normal N at chart point x4.
  V3 local_normal(const double* x4, const ObserverFrame& f, V3 N) const {
    double nc[3] = {N.x, N.y, N.z};  // covector in the chart: n_j = N_i dUser_i / dChart_j
    if constexpr (!M::kUserIsChart) {
      double J[3][3];
      chart_jacobian(x4, J);
      for (int j = 0; j < 3; ++j) nc[j] = N.x * J[0][j] + N.y * J[1][j] + N.z * J[2][j];
    }
    V3 n;
    for (int a = 0; a < 3; ++a) n[a] = f.e[a][1] * nc[0] + f.e[a][2] * nc[1] + f.e[a][3] * nc[2];
    return normalize(n);
  }

  // J_ij = d user_i / d chart_j by central differences (charts that are not the user frame).
  void chart_jacobian(const double* x4, double J[3][3]) const {
    const double r = std::sqrt(x4[1] * x4[1] + x4[2] * x4[2] + x4[3] * x4[3]);
    const double eps = 1e-6 * std::max(1.0, r);
    for (int j = 0; j < 3; ++j) {
      double xp[4] = {x4[0], x4[1], x4[2], x4[3]}, xm[4] = {x4[0], x4[1], x4[2], x4[3]};
      xp[1 + j] += eps;
      xm[1 + j] -= eps;
      double pp[3], pm[3];
      m_.chart_to_user(xp, 1, pp);
      m_.chart_to_user(xm, 1, pm);
      for (int i = 0; i < 3; ++i) J[i][j] = (pp[i] - pm[i]) / (2.0 * eps);
    }
  }
  void chart_jacobian_inverse(const double* x4, double jinv[3][3]) const {
    double J[3][3];
    chart_jacobian(x4, J);
    const double det = J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
                       J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
                       J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const int i1 = (j + 1) % 3, i2 = (j + 2) % 3, j1 = (i + 1) % 3, j2 = (i + 2) % 3;
        jinv[i][j] = (J[i1][j1] * J[i2][j2] - J[i1][j2] * J[i2][j1]) / det;
      }
  }

  StartFrames::Entry start_frame(V3 x, int sheet) const {
    StartFrames::Entry s;
    s.pos = x;
    s.sheet = sheet;
    s.ok = m_.user_to_chart(&x.x, sheet, s.x4) && observer_frame(m_, s.x4, s.f) && !m_.absorbed(s.x4);
    return s;
  }

  // State of a ray traced backwards from user-frame point x along local direction d: the future-directed
  // momentum of light arriving there along d, negated. False on or inside a horizon.
  bool backward_state(V3 x, int sheet, V3 d, double y[8], StartFrames& frames) const {
    return start_state(x, sheet, d, y, frames, true);
  }
  // State of light leaving user-frame point x along local direction d, forward in time (a photon from a light).
  bool forward_state(V3 x, int sheet, V3 d, double y[8], StartFrames& frames) const {
    return start_state(x, sheet, d, y, frames, false);
  }

 private:
  bool start_state(V3 x, int sheet, V3 d, double y[8], StartFrames& frames, bool backward) const {
    const StartFrames::Entry* s = nullptr;
    for (int i = 0; i < frames.n && !s; ++i)
      if (frames.e[i].pos.x == x.x && frames.e[i].pos.y == x.y && frames.e[i].pos.z == x.z &&
          frames.e[i].sheet == sheet)
        s = &frames.e[i];
    if (!s) {
      const int slot = frames.next;
      frames.e[slot] = start_frame(x, sheet);
      frames.next = (slot + 1) % StartFrames::kSize;
      frames.n = std::max(frames.n, slot + 1);
      s = &frames.e[slot];
    }
    if (!s->ok) return false;
    const double sign = backward ? -1.0 : 1.0;
    const double dir[3] = {sign * d.x, sign * d.y, sign * d.z};
    for (int i = 0; i < 4; ++i) y[i] = s->x4[i];
    frame_to_momentum(s->f, dir, y + 4);
    if (backward)
      for (int i = 4; i < 8; ++i) y[i] = -y[i];
    return true;
  }

  const M& m_;
};

// The local static frame at a point light: the map of user-frame displacements into it and the spot's axis
// there (ok false: the light is not in the chart or has no static observer, and sends nothing).
struct PointLightFrame {
  bool ok = false;
  LinearMap to_local;
  V3 axis_local{0, 0, 1};
};

template <class M>
std::vector<PointLightFrame> point_light_frames(const M& m, const Scene& sc) {
  std::vector<PointLightFrame> out(sc.point_lights.size());
  const ChartGeometry<M> geo(m);
  for (size_t k = 0; k < out.size(); ++k) {
    const PointLight& pl = sc.point_lights[k];
    PointLightFrame& f = out[k];
    if constexpr (M::kFlat) {
      f.ok = true;
      f.axis_local = pl.axis;
    } else {
      const StartFrames::Entry s = geo.start_frame(pl.pos, pl.sheet);
      f.ok = s.ok;
      if (!f.ok) continue;
      f.to_local = geo.local_map(s.x4, s.f);
      f.axis_local = normalize(f.to_local(pl.axis));
    }
  }
  return out;
}

}  // namespace wv
