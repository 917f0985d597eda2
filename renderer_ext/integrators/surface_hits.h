// Scene surfaces along curved rays. For each accepted integration step, one BVH query finds the
// primitives near the step (its bounding box grown by the arc's bulge; usually none). Only then is the
// arc cut into chords short enough that it deviates from them by at most the chord tolerance, each chord
// tested exactly against those primitives, and a chord hit refined on the step's dense output (a
// bracketed root of the surface's implicit function along the arc) to ~1e-12 M.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/root.h"
#include "scene/scene.h"

namespace wv {

// Where a curve parametrised by t in [ta, tb] first crosses a surface, f(t) its implicit function there
// (a distance), starting the search from the chord's estimate tg: scan from ta for the first sign change,
// probing near tg first, then (where the chord left the shape again, at the estimate tg_out > tg) across the
// chord's span inside it, then finely over [ta, tb]; then the Illinois crossing to within 1e-14 in t or ftol()
// in f, ftol evaluated after the scan. False: the curve misses what the chord grazed. The span's probes find a
// small ball that a long chord passes through with both ends outside it, which the fine scan's 32 probes step
// over (a ball behind a hole, lensed into thin arcs).
template <class F, class Tol>
bool curve_crossing(const F& f, const Tol& ftol, double ta, double tb, double tg, double& theta,
                    double tg_out = -1.0) {
  const double fa = f(ta), width = tb - ta;
  double lo = ta, flo = fa, hi = -1.0, fhi = 0.0;
  auto scan = [&](const double* ts, int n) {
    double pt = ta, pf = fa;
    for (int i = 0; i < n; ++i) {
      const double t = ts[i];
      if (t <= pt || t > tb) continue;
      const double ft = f(t);
      if ((ft < 0.0) != (pf < 0.0)) {
        lo = pt;
        flo = pf;
        hi = t;
        fhi = ft;
        return true;
      }
      pt = t;
      pf = ft;
    }
    return false;
  };
  const double probes[] = {tg - 0.02 * width, tg + 0.02 * width, tg + 0.1 * width, tb};
  bool found = scan(probes, 4);
  if (!found && tg_out > tg) {
    constexpr int kSpan = 16;
    double span[kSpan];
    for (int i = 0; i < kSpan; ++i) span[i] = tg + (tg_out - tg) * (i + 0.5) / kSpan;
    found = scan(span, kSpan);
  }
  if (!found) {
    double fine[32];
    for (int i = 0; i < 32; ++i) fine[i] = ta + width * (i + 1) / 32.0;
    if (!scan(fine, 32)) return false;
  }
  theta = crossing(f, lo, flo, hi, fhi, 1e-14, ftol());
  return true;
}

// Where the chord o + t d, having entered primitive p at t, leaves it again before t = 1 (a closed shape: a
// ball, a cylinder), or -1.
inline double chord_exit(const Scene& sc, int p, V3 o, V3 d, double t) {
  double t2;
  return sc.intersect_prim(p, o, d, t + 1e-9, 1.0, t2) ? t2 : -1.0;
}

// The hits of the chord o + t d, t in (0, 1), on candidate primitives of `sheet`, nearest first (into hits,
// which holds nc); skipped(p, t) drops one (the surface a ray just left). Returns their number.
template <class Skip>
int chord_hits(const Scene& sc, V3 o, V3 d, const int* cand, int nc, int sheet, const Skip& skipped,
               SegmentHit* hits) {
  int nh = 0;
  for (int c = 0; c < nc; ++c) {
    const int p = cand[c];
    double t;
    if (sc.prims[p].sheet != sheet || !sc.intersect_prim(p, o, d, 0.0, 1.0, t)) continue;
    if (skipped(p, t)) continue;
    int at = nh++;
    while (at > 0 && hits[at - 1].t > t) {
      hits[at] = hits[at - 1];
      --at;
    }
    hits[at] = {p, t};
  }
  return nh;
}

template <class M>
struct SceneSurfaces {
  static constexpr bool kActive = true;
  // The state at a hit is the step's dense output there, on which the hit was found: dopri5's and dop853's
  // continuous extensions are as accurate as their steps (kAccurateDense), so the momentum the next segment
  // leaves with is as good as a full-order step to the hit would give (and rk4's Hermite output still
  // takes that step). The step cost 4-6 % of a Kerr room's time for nothing the tolerance could see.
  static constexpr bool kDenseEnd = true;
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
    // Quick reject: the step's end points and bulge lie outside the scene's bounding sphere. The bulge
    // is the chord's distance from the arc's (cubic Hermite) midpoint.
    st.midpoint(y, ynew, h, ys);
    m.chart_to_user(ys, sheet, pm_);
    const V3 pm(pm_);
    const double sag = length(pm - (p0 + p1) * 0.5);
    const double R = sc.bound_radius;
    const double near2 = std::min(std::min(dot(p0, p0), dot(p1, p1)), dot(pm, pm));
    if (near2 > R * R) {  // (inside the bounding sphere, as in a room, the reach test cannot pass: skip it)
      const double reach = std::sqrt(near2) - length(p1 - p0) - sag;
      if (reach > R) return false;
    }
    // Broad phase: one BVH query for the primitives whose boxes meet the step's box, grown by the bulge.
    Box box;
    box.extend(p0);
    box.extend(p1);
    box.extend(pm);
    const V3 d01 = p1 - p0;
    const double pad = 1.5 * sag + 1e-9 * (1.0 + std::fabs(d01.x) + std::fabs(d01.y) + std::fabs(d01.z));
    box.lo = box.lo - V3{pad, pad, pad};
    box.hi = box.hi + V3{pad, pad, pad};
    constexpr int kMaxCandidates = 32;
    int cand[kMaxCandidates];
    int nc = 0;
    bool overflow = false;
    sc.bvh.overlapping(box, [&](int p) {
      if (nc < kMaxCandidates) cand[nc++] = p; else overflow = true;
    });
    if (nc == 0) return false;
    // Narrow phase: the arc cut into chords whose sagitta is at most chord_tol, each tested exactly
    // against the candidates (or against the whole BVH when there are too many of them).
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
      const V3 d = pb - pa;
      const double len = length(d);
      if (sa == sb && len > 0.0) {
        const double skip_t = (first && k == 0) ? skip_dist / len : 0.0;
        // chord hits in this sub-interval, nearest first
        SegmentHit hits[kMaxCandidates];
        int nh = 0;
        if (overflow) {
          if (sc.closest_hit(pa, d, 0.0, 1.0, sa, skip_prim, skip_t, hits[0])) nh = 1;
        } else {
          auto skip_hit = [&](int p, double t) { return p == skip_prim && t < skip_t; };
          nh = chord_hits(sc, pa, d, cand, nc, sa, skip_hit, hits);
        }
        for (int c = 0; c < nh; ++c) {
          const double out = chord_exit(sc, hits[c].prim, pa, d, hits[c].t);
          if (refine(st, y, ynew, h, sheet, hits[c].prim, ta, tb, ta + hits[c].t * (tb - ta), theta,
                     out > 0.0 ? ta + out * (tb - ta) : -1.0)) {
            prim = hits[c].prim;
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
              double tg, double& theta, double tg_out) const {
    double ys[8], q[3];
    auto f = [&](double t) {
      st.dense(y, ynew, h, t, ys);
      m.chart_to_user(ys, sheet, q);
      return sc.implicit_at(p, V3(q));
    };
    // |f| is a distance (unit-normal planes, |p - c| - R for spheres): stop at 1e-12 M
    return curve_crossing(f, [&] { return 1e-12 * (1.0 + length(V3(q))); }, ta, tb, tg, theta, tg_out);
  }
};

}  // namespace wv
