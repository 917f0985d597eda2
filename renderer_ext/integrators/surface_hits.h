// Scene surfaces along curved rays: each accepted integration step is cut into chords short enough that
// the arc deviates from them by at most the chord tolerance; each chord is tested against the scene's
// BVH, and a chord hit is refined on the step's dense output (bisection of the surface's implicit
// function along the arc) so the crossing is located to ~1e-12 of the step.
#pragma once

#include <algorithm>
#include <cmath>

#include "scene/scene.h"

namespace wv {

template <class M>
struct SceneSurfaces {
  static constexpr bool kActive = true;
  const M& m;
  const Scene& sc;
  double chord_tol;   // largest allowed sagitta of a chord (user-frame length)
  int skip_prim;      // primitive the ray starts on ...
  double skip_dist;   // ... ignored within this distance of the start
  bool first_step = true;

  SceneSurfaces(const M& metric, const Scene& scene, double tol, int skip, double skip_d)
      : m(metric), sc(scene), chord_tol(tol), skip_prim(skip), skip_dist(skip_d) {}

  template <class S>
  bool find(const S& st, const double* y, const double* ynew, double h, int sheet, double& theta, int& prim) {
    const bool first = first_step;
    first_step = false;
    double ys[8], pa_[3], pb_[3], pm_[3];
    const int sa0 = m.chart_to_user(y, sheet, pa_);
    const int sb0 = m.chart_to_user(ynew, sheet, pb_);
    const V3 p0(pa_), p1(pb_);
    // Quick reject: the step's end points and bulge lie outside the scene's bounding sphere.
    st.dense(y, ynew, h, 0.5, ys);
    m.chart_to_user(ys, sheet, pm_);
    const V3 pm(pm_);
    const double sag = length(pm - (p0 + p1) * 0.5);
    const double R = sc.bound_radius;
    const double reach = std::min(std::min(length(p0), length(p1)), length(pm)) - length(p1 - p0) - sag;
    if (reach > R) return false;
    const int n = sag <= chord_tol ? 1 : std::min(64, int(std::ceil(std::sqrt(sag / chord_tol))));
    V3 pa = p0;
    int sa = sa0;
    for (int k = 0; k < n; ++k) {
      const double ta = double(k) / n, tb = double(k + 1) / n;
      V3 pb;
      int sb;
      if (k + 1 == n) {
        pb = p1;
        sb = sb0;
      } else {
        st.dense(y, ynew, h, tb, ys);
        double q[3];
        sb = m.chart_to_user(ys, sheet, q);
        pb = V3(q);
      }
      if (sa == sb) {
        const V3 d = pb - pa;
        const double len = length(d);
        SegmentHit hit;
        const double skip_t = (first && k == 0 && len > 0.0) ? skip_dist / len : 0.0;
        if (len > 0.0 && sc.closest_hit(pa, d, 0.0, 1.0, sa, skip_prim, skip_t, hit)) {
          if (refine(st, y, ynew, h, sheet, hit.prim, ta, tb, ta + hit.t * (tb - ta), theta)) {
            prim = hit.prim;
            return true;
          }
        }
      }
      pa = pb;
      sa = sb;
    }
    return false;
  }

  // Crossing of primitive p's implicit surface by the arc within [ta, tb] (step fractions), starting
  // the search from the chord's estimate tg.
  template <class S>
  bool refine(const S& st, const double* y, const double* ynew, double h, int sheet, int p, double ta, double tb,
              double tg, double& theta) const {
    double ys[8], q[3];
    auto f = [&](double t) {
      st.dense(y, ynew, h, t, ys);
      m.chart_to_user(ys, sheet, q);
      return sc.implicit_at(p, V3(q));
    };
    // Bracket: scan the arc from ta for the first sign change, probing near the chord estimate first.
    const double fa = f(ta);
    double lo = ta, hi = -1.0;
    const double width = tb - ta;
    const double probes[] = {tg - 0.02 * width, tg + 0.02 * width, tg + 0.1 * width, tb};
    double prev_t = ta, prev_f = fa;
    for (double t : probes) {
      if (t <= prev_t || t > tb) continue;
      const double ft = f(t);
      if ((ft < 0.0) != (prev_f < 0.0)) {
        lo = prev_t;
        hi = t;
        break;
      }
      prev_t = t;
      prev_f = ft;
    }
    if (hi < 0.0) {  // chord crossed twice within a probe interval: scan finely
      const int N = 32;
      prev_t = ta;
      prev_f = fa;
      for (int i = 1; i <= N; ++i) {
        const double t = ta + width * i / N;
        const double ft = f(t);
        if ((ft < 0.0) != (prev_f < 0.0)) {
          lo = prev_t;
          hi = t;
          break;
        }
        prev_t = t;
        prev_f = ft;
      }
      if (hi < 0.0) return false;  // the arc misses what the chord grazed
    }
    const bool neg_lo = f(lo) < 0.0;
    for (int it = 0; it < 60 && hi - lo > 1e-14; ++it) {
      const double mid = 0.5 * (lo + hi);
      if ((f(mid) < 0.0) == neg_lo) lo = mid; else hi = mid;
    }
    theta = hi;
    return true;
  }
};

}  // namespace wv
