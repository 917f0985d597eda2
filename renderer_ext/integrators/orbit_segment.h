// Geodesic segments in closed form, for the static spherical metrics whose light orbits are
// spacetime/planar_orbit.h's (Schwarzschild's cubic): the ray stays in the plane of the centre, its start
// and its direction, where u = 1/R is an elliptic function of the azimuth phi, so any point of the segment
// is one evaluation and nothing is integrated. The segment is searched for surfaces by bisection in phi:
// a piece of the arc lies in the triangle of its chord and its end tangents (the orbit's curvature keeps
// one sign), so its chord's box grown by that triangle's height h = (c/2) tan(turn/2) bounds it; a piece
// whose box meets no primitive is done, one with h above the chord tolerance is halved, and a chord within
// the tolerance is tested exactly against the candidates, a chord hit refined on the orbit itself
// (curve_crossing, to ~1e-12 M). The same tolerance rule as the integrated segments (surface_hits.h),
// with exact positions in between.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/trig.h"
#include "core/vec3.h"
#include "integrators/surface_hits.h"
#include "scene/scene.h"
#include "spacetime/geodesic.h"
#include "spacetime/planar_orbit.h"

namespace wv {

// Where a closed-form segment ended: hit (prim, pos, the local-frame direction of travel), escaped (the
// direction on the sky) or horizon.
struct OrbitEnd {
  int status = kNaN;
  int prim = -1;
  V3 pos;
  V3 dir;
};

// Where a segment is aimed (a light sample of the lens connection, lens_connection.h): the point on primitive
// `prim` that the ray reaches after sweeping `sweep` about the centre (its image's Phi; negative: no aim).
struct OrbitAim {
  int prim = -1;
  V3 point;
  double sweep = -1.0;
};

template <class M>
class OrbitSegments {
 public:
  // M's lens polynomial must be Schwarzschild's cubic in a chart that is the user frame on one sheet, with
  // the centre at the origin (the static observer's radial axis then points along the user radius).
  static constexpr bool kPossible = !M::kFlat && M::kStaticSpherical && M::kUserIsChart && M::kSheets == 1;

  OrbitSegments(const M& m, const Scene& sc, double chord_tol, double escape_radius)
      : sc_(sc), chord_tol_(chord_tol), escape_radius_(escape_radius) {
    if constexpr (kPossible) {
      mass_ = m.spherical_lens().cubic_mass();
      capture_ = m.capture_radius();
    } else {
      (void)m;
    }
  }

  bool active() const { return mass_ > 0.0; }
  double escape_radius() const { return escape_radius_; }

  // The segment of backward chart state y (at user point x = y[1..3]); false where the closed form does
  // not apply (the caller integrates): a start at or below the capture radius, rays near the critical
  // impact parameter or near-radial ones. dxdl is the ray's coordinate velocity dx/dlambda. With an aim the
  // orbit is searched only up to the aimed point (aimed()).
  bool trace(const double y[8], const double dxdl[3], int sheet, int skip, double skip_dist, OrbitEnd& e,
             const OrbitAim& aim = {}) const {
    if constexpr (!kPossible) {
      (void)y, (void)dxdl, (void)sheet, (void)skip, (void)skip_dist, (void)e, (void)aim;
      return false;
    } else {
      return trace_orbit(y, dxdl, sheet, skip, skip_dist, e, aim);
    }
  }

 private:
  bool trace_orbit(const double y[8], const double dxdl[3], int sheet, int skip, double skip_dist, OrbitEnd& e,
                   const OrbitAim& aim) const {
    const V3 X(y[1], y[2], y[3]);
    const double r0 = length(X);
    if (!(r0 > capture_ * (1.0 + 1e-9))) return false;
    const V3 p(y[5], y[6], y[7]);
    const V3 L = cross(X, p);  // the angular momentum, normal to the orbit's plane
    const double Ln = length(L), E = std::fabs(y[4]);
    if (!(Ln > 0.0 && E > 0.0)) return false;
    const double b = Ln / E;
    const bool inward = X.x * dxdl[0] + X.y * dxdl[1] + X.z * dxdl[2] < 0.0;
    Walk w(*this, PlanarOrbit(mass_, b, 1.0 / r0, inward));
    if (!w.orb.valid()) return false;
    w.e1 = X * (1.0 / r0);
    w.e2 = normalize(cross(L * (1.0 / Ln), w.e1));
    if (!(dot(w.e2, V3(dxdl[0], dxdl[1], dxdl[2])) > 0.0)) return false;  // (phi grows along the ray)
    w.sheet = sheet;
    w.skip = skip;
    w.skip_dist = skip_dist;
    w.x0 = X;
    if (aim.prim >= 0 && aimed(w, b, r0, aim, e)) return true;

    // The part of the orbit inside the scene's bounding sphere, and how the ray ends.
    const double u0 = 1.0 / r0, uR = 1.0 / (sc_.bound_radius * (1.0 + 1e-9) + 1e-12);
    const double ucap = 1.0 / capture_;
    double start = u0 >= uR ? 0.0 : w.orb.phi_of(uR, false), end;
    const double to_capture = w.orb.phi_of(ucap, false);
    if (std::isfinite(to_capture)) {
      end = to_capture;  // falls in (or dips below the capture radius, which the integrator absorbs too)
      e.status = kHorizon;
    } else {
      end = w.orb.phi_of(uR, true);
      e.status = kEscaped;
      if (w.orb.falls_in()) return false;  // (a ray falling in reaches the capture radius: rounding; integrate)
    }
    int prim = -1;
    double phi_hit = 0.0;
    if (std::isfinite(start) && std::isfinite(end) && end > start) {
      const OrbitPoint a = w.at(start), z = w.at(end);
      if (!(std::isfinite(a.u) && std::isfinite(z.u))) return false;
      if (w.piece(a, z, 0, nullptr, 0, prim, phi_hit) < 0) return false;
    }
    if (prim >= 0) {
      hit(w, b, prim, w.at(phi_hit), e);
      return true;
    }
    if (e.status == kEscaped) {
      const double inf = w.orb.phi_of(0.0, true);
      const double esc = w.orb.phi_of(1.0 / escape_radius_, true);
      if (!std::isfinite(inf)) return false;
      e.dir = w.e1 * std::cos(inf) + w.e2 * std::sin(inf);
      e.pos = std::isfinite(esc) ? w.at(esc).x : X;
    } else {
      e.pos = w.at(end).x;
    }
    return true;
  }

  struct OrbitPoint {
    double phi = 0.0, u = 0.0, du = 0.0;
    double px = 0.0, py = 0.0, tx = 0.0, ty = 0.0;  // in the plane: position, unit tangent
    V3 x, t;                                         // user frame: position, unit tangent
  };

  static constexpr int kMaxCandidates = 32;

  struct Walk {
    Walk(const OrbitSegments& segments, const PlanarOrbit& orbit) : s(segments), orb(orbit) {}
    const OrbitSegments& s;
    PlanarOrbit orb;
    V3 e1, e2, x0;
    int sheet = 1, skip = -1;
    double skip_dist = 0.0;

    // The orbit at phi: u, du/dphi and the plane's polar directions (radial r, azimuthal a), in the user
    // frame; the position is r / u.
    struct Polar {
      double u, du, c, s;
      V3 r, a;
      V3 x() const { return r * (1.0 / u); }
      V3 dx() const { return a * (1.0 / u) - r * (du / (u * u)); }  // dX/dphi
    };
    Polar polar(double phi) const {
      Polar q;
      q.u = orb.u(phi, &q.du);
      sin_cos(phi, q.s, q.c);
      q.r = e1 * q.c + e2 * q.s;
      q.a = e2 * q.c - e1 * q.s;
      return q;
    }

    OrbitPoint at(double phi) const {
      const Polar q = polar(phi);
      OrbitPoint p;
      p.phi = phi;
      p.u = q.u;
      p.du = q.du;
      p.px = q.c / q.u;
      p.py = q.s / q.u;
      // d/dphi of (cos, sin) / u, times u^2
      const double tx = -q.s * q.u - q.c * q.du, ty = q.c * q.u - q.s * q.du;
      const double tn = 1.0 / std::sqrt(tx * tx + ty * ty);
      p.tx = tx * tn;
      p.ty = ty * tn;
      p.x = q.x();
      p.t = e1 * p.tx + e2 * p.ty;
      return p;
    }
    V3 pos(double phi) const { return polar(phi).x(); }
    bool skipped(int p, V3 x) const { return p == skip && length(x - x0) < skip_dist; }

    // The first hit on the arc from a to b (prim, phi): 1 hit, 0 none, -1 the walk failed. cand: the
    // primitives the enclosing piece could not rule out (null: query the BVH).
    int piece(const OrbitPoint& a, const OrbitPoint& b, int depth, const int* cand, int nc, int& prim,
              double& phi_hit) const {
      constexpr int kMaxDepth = 48;
      // The arc turns by less than 1.47 rad (cos > 0.1) in a piece, so it lies in the triangle of its chord
      // and end tangents: within h of the chord, and at most S long.
      const double cr = std::fabs(a.tx * b.ty - a.ty * b.tx), dt = a.tx * b.tx + a.ty * b.ty;
      if (b.phi - a.phi > 2.0 || !(dt > 0.1)) {
        if (depth >= kMaxDepth) return -1;
        return halves(a, b, depth, cand, nc, prim, phi_hit);
      }
      const double dx = b.px - a.px, dy = b.py - a.py;
      const double c = std::sqrt(dx * dx + dy * dy);
      const double h = 0.5 * c * cr / (1.0 + dt) + 1e-9 * (1.0 + std::fabs(a.px) + std::fabs(a.py) + c);
      const double S = c * std::sqrt(2.0 / (1.0 + dt));
      int live[kMaxCandidates];
      int nl = 0;
      bool overflow = false;
      if (!cand) {
        Box box;
        box.extend(a.x);
        box.extend(b.x);
        box.lo = box.lo - V3{h, h, h};
        box.hi = box.hi + V3{h, h, h};
        s.sc_.bvh.overlapping(box, [&](int p) {
          if (nl < kMaxCandidates) live[nl++] = p; else overflow = true;
        });
        if (overflow) return crowded(a, b, depth, h, prim, phi_hit);
      } else {
        for (int k = 0; k < nc; ++k) live[nl++] = cand[k];
      }
      // Rule out what the piece cannot meet, and find where it crosses a plane it crosses once.
      const double kappa = orb.curvature_bound(std::max(a.u, b.u), a.du > 0.0 && b.du < 0.0);
      const double bend = 0.5 * kappa * S * S;
      int keep[kMaxCandidates];
      int nk = 0, unresolved = 0;
      // The planes crossed once, by the azimuth where the chord crosses them: found on the orbit only once
      // nothing else is left unresolved (else the piece is halved and they are tested again in the halves).
      struct Crossing {
        int p;
        const V3* n;
        double fa, fb, start, spread;  // the chord's crossing's azimuth, and how far the orbit's can be from it
      };
      Crossing cross[kMaxCandidates];
      int ncross = 0;
      for (int k = 0; k < nl; ++k) {
        const int p = live[k];
        if (s.sc_.prims[p].sheet != sheet) continue;
        const V3* n = s.sc_.plane_normal(p);
        if (!n) {  // a sphere: the arc stays within h of its chord
          const Sphere& sp = s.sc_.spheres[s.sc_.prims[p].index];
          const V3 d = b.x - a.x;
          const double w = std::max(0.0, std::min(1.0, dot(sp.center - a.x, d) / std::max(dot(d, d), 1e-300)));
          const double near = length(a.x + d * w - sp.center);
          const double far = std::max(length(a.x - sp.center), length(b.x - sp.center));
          if (near - h > sp.radius || far + h < sp.radius) continue;
          keep[nk++] = p;
          ++unresolved;
          continue;
        }
        // A plane: f, the signed distance, is linear along the chord and has |f''| <= kappa along the
        // arc (unit speed), with f' = n.t at the ends.
        const double fa = s.sc_.implicit_at(p, a.x), fb = s.sc_.implicit_at(p, b.x);
        if (std::min(fa, fb) > h || std::max(fa, fb) < -h) continue;
        const double da = dot(*n, a.t), db = dot(*n, b.t);
        if ((fa > 0.0 && fa + da * S - bend > 0.0) || (fa < 0.0 && fa + da * S + bend < 0.0) ||
            (fb > 0.0 && fb - db * S - bend > 0.0) || (fb < 0.0 && fb - db * S + bend < 0.0))
          continue;
        if ((fa < 0.0) != (fb < 0.0) && da * db > 0.0) {
          // One crossing (f' keeps its sign: the tangent turns by less than pi). It lies within
          // h (1 + |chord| / |fa - fb|) of the chord's: if the primitive is farther than that from the
          // chord's crossing it is missed; else the crossing is found on the orbit and tested against
          // the primitive's edges by a short chord through it along the normal.
          const V3 d = b.x - a.x;
          const V3 pc = a.x + d * (fa / (fa - fb));
          const double reach = h * (1.0 + length(d) / std::fabs(fa - fb)) + 1e-9 * (1.0 + length(pc));
          if (s.sc_.plane_gap(p, pc) > reach) continue;
          keep[nk++] = p;
          // The root starts at the azimuth of the chord's crossing: the arc is within h of the chord there (a
          // start interpolated in phi is farther off and costs ~2 more evaluations; the crossing of the cubic
          // Bezier curve of the ends and their tangents saves 0.3 of fig07's 2.3 evaluations per crossing but
          // costs more than they do). The orbit's crossing, within `reach` of pc, is within asin(reach / |pc|)
          // <= (pi / 2) reach / |pc| of its azimuth.
          const double cx = dot(pc, e1), cy = dot(pc, e2), rc = std::sqrt(cx * cx + cy * cy);
          const double start = a.phi + std::atan2(a.px * cy - a.py * cx, a.px * cx + a.py * cy);
          const double spread = reach < rc ? 0.5 * M_PI * reach / rc : INFINITY;
          int at = ncross++;
          while (at > 0 && cross[at - 1].start > start) {
            cross[at] = cross[at - 1];
            --at;
          }
          cross[at] = {p, n, fa, fb, start, spread};
          continue;
        }
        keep[nk++] = p;
        ++unresolved;
      }
      if (unresolved == 0) {
        // Nearest first: a plane whose crossing cannot come before the hit found is not solved for.
        int best = -1;
        double best_phi = INFINITY;
        for (int k = 0; k < ncross; ++k) {
          const Crossing& q = cross[k];
          if (q.start - q.spread > best_phi) continue;
          const V3 n = *q.n;
          V3 x;
          const double th = plane_crossing(q.p, n, a.phi, q.fa, b.phi, q.fb, q.start, 1e-12 * (1.0 + length(a.x) + c), x);
          if (th < best_phi && within(q.p, n, x) && !skipped(q.p, x)) {
            best_phi = th;
            best = q.p;
          }
        }
        if (best < 0) return 0;
        prim = best;
        phi_hit = best_phi;
        return 1;
      }
      if (h > s.chord_tol_ && depth < kMaxDepth) return halves(a, b, depth, keep, nk, prim, phi_hit);
      return chord(a, b, keep, nk, prim, phi_hit);
    }

    // Whether point x, on the plane (normal n) of primitive p to within its crossing's tolerance, lies within p's
    // edges: a short chord through it along the normal, tested exactly against p.
    bool within(int p, V3 n, V3 x) const {
      const double eps = 1e-6 * (1.0 + length(x));
      const V3 foot = x - n * s.sc_.implicit_at(p, x);
      double t;
      return s.sc_.intersect_prim(p, foot + n * eps, n * (-2.0 * eps), 0.0, 1.0, t);
    }

    // The root of the Taylor parabola in phi of f, the signed distance to a plane of normal n, about orbit point q
    // where it is f (f'' from the orbit equation u'' = 3 M u^2 - u): the step from q, a bound on how far from the
    // plane it lands (|f'''| step^3 / 6 with u''' = (6 M u - 1) u', plus the parabola's own residual there), its
    // point along the orbit's Taylor parabola, and f' at q (0: no step). A Newton step's error is |f''| step^2 / 2:
    // from the parabola a root ~1e-4 away is within the tolerance where the tangent's was only ~1e-6 away.
    struct TaylorRoot {
      double df = 0.0, step = 0.0, error = INFINITY;
      V3 x;
    };
    TaylorRoot taylor_root(const Polar& q, V3 n, double f) const {
      TaylorRoot r;
      const V3 dx = q.dx();
      r.df = dot(n, dx);
      if (r.df == 0.0) return r;
      const double df = r.df;
      const double iu = 1.0 / q.u, iu2 = iu * iu, u1 = q.du, u2 = orb.ddu(q.u), u3 = orb.dddu(q.u, u1);
      const double P = -iu - u2 * iu2 + 2.0 * u1 * u1 * iu2 * iu, Q = -2.0 * u1 * iu2;
      const V3 ddx = q.r * P + q.a * Q;  // d2X/dphi2
      const double dP = u1 * iu2 - u3 * iu2 + 6.0 * u1 * u2 * iu2 * iu - 6.0 * u1 * u1 * u1 * iu2 * iu2,
                   dQ = -2.0 * u2 * iu2 + 4.0 * u1 * u1 * iu2 * iu;
      const V3 dddx = q.r * (dP - Q) + q.a * (P + dQ);  // d3X/dphi3
      const double df2 = dot(n, ddx);
      double step = -f / df;
      step = -(f + 0.5 * df2 * step * step) / df;
      step = -(f + 0.5 * df2 * step * step) / df;  // (two fixed-point steps to the parabola's root)
      const double miss = std::fabs(f + step * (df + 0.5 * df2 * step));  // the parabola's own, at the step
      r.step = step;
      r.error = std::fabs(dot(n, dddx)) * std::fabs(step * step * step) + miss;
      r.x = q.x() + dx * step + ddx * (0.5 * step * step);
      return r;
    }

    // Where the orbit crosses the plane of primitive p (normal n) between lo and hi (f(lo) = flo and
    // f(hi) = fhi of opposite signs, f' of one sign), from start: the root of f's Taylor parabola in phi
    // (the orbit's exact first and second derivatives; Newton's step where the parabola's is far longer),
    // kept inside the bracket (a secant step where it would leave it). Returns the azimuth (at_ its
    // position) where |f| <= ftol, or the last step taken along the orbit's Taylor parabola where its third
    // derivative bounds that step's error by ftol: f is a distance, and the point may be on either side,
    // since the next segment starts off the surface by far more.
    double plane_crossing(int p, V3 n, double lo, double flo, double hi, double fhi, double start, double ftol,
                          V3& at_) const {
      double t = start > lo && start < hi ? start : lo + (hi - lo) * flo / (flo - fhi);
      for (int it = 0; it < 60; ++it) {
        if (!(t > lo && t < hi)) t = 0.5 * (lo + hi);
        const Polar q = polar(t);
        const V3 x = q.x();
        const double f = s.sc_.implicit_at(p, x);
        at_ = x;
        if (std::fabs(f) <= ftol) return t;
        if ((f < 0.0) == (fhi < 0.0)) {
          hi = t;
          fhi = f;
        } else {
          lo = t;
          flo = f;
        }
        if (hi - lo <= 1e-15 * (1.0 + std::fabs(hi))) return t;
        // Close enough that the step to the root of f's Taylor parabola about t is within the tolerance: taken
        // along the orbit's Taylor parabola instead of evaluating the orbit once more to confirm it.
        const TaylorRoot tr = taylor_root(q, n, f);
        const double df = tr.df;
        if (df != 0.0) {
          const double next = t + tr.step;
          if (next > lo && next < hi && tr.error <= ftol) {
            at_ = tr.x;
            return next;
          }
          if (std::isfinite(next) && std::fabs(tr.step) <= 2.0 * std::fabs(f / df)) {
            t = next;
            if (!(t > lo && t < hi)) t = lo + (hi - lo) * flo / (flo - fhi);
            continue;
          }
        }
        t = df != 0.0 ? t - f / df : 0.5 * (lo + hi);
        if (!(t > lo && t < hi)) t = lo + (hi - lo) * flo / (flo - fhi);
      }
      return t;
    }

    // The chord from a to b (within the chord tolerance of the arc) tested exactly against candidates;
    // its hits, nearest first, refined on the orbit.
    int chord(const OrbitPoint& a, const OrbitPoint& b, const int* cand, int nc, int& prim, double& phi_hit) const {
      const V3 d = b.x - a.x;
      const double len = length(d);
      if (!(len > 0.0)) return 0;
      SegmentHit hits[kMaxCandidates];
      int nh = 0;
      if (!cand) {  // more candidates than the lists hold: the whole BVH
        const double skip_t = a.phi == 0.0 ? skip_dist / len : 0.0;
        if (s.sc_.closest_hit(a.x, d, 0.0, 1.0, sheet, skip, skip_t, hits[0])) nh = 1;
      } else {
        auto skip_hit = [&](int p, double t) { return skipped(p, a.x + d * t); };
        nh = chord_hits(s.sc_, a.x, d, cand, nc, sheet, skip_hit, hits);
      }
      for (int k = 0; k < nh; ++k) {
        const int p = hits[k].prim;
        V3 q;
        auto f = [&](double phi) {
          q = pos(phi);
          return s.sc_.implicit_at(p, q);
        };
        // The chord's entry (and exit, from a ball) as azimuths: where the chord's point lies round the centre.
        auto phi_at = [&](double t) {
          const V3 x = a.x + d * t;
          const double cx = dot(x, e1), cy = dot(x, e2);
          return a.phi + std::atan2(a.px * cy - a.py * cx, a.px * cx + a.py * cy);
        };
        const double out = chord_exit(s.sc_, p, a.x, d, hits[k].t);
        double th;
        if (curve_crossing(f, [&] { return 1e-12 * (1.0 + length(q)); }, a.phi, b.phi, phi_at(hits[k].t), th,
                           out > 0.0 ? phi_at(out) : -1.0)) {
          if (skipped(p, pos(th))) continue;
          prim = p;
          phi_hit = th;
          return 1;
        }
      }
      return 0;
    }

    // A piece whose box meets more primitives than the lists hold (a mesh): halved with a BVH query per
    // piece down to the chord tolerance, then the chord against the whole BVH.
    int crowded(const OrbitPoint& a, const OrbitPoint& b, int depth, double h, int& prim, double& phi_hit) const {
      if (h > s.chord_tol_ && depth < 48) return halves(a, b, depth, nullptr, 0, prim, phi_hit);
      return chord(a, b, nullptr, 0, prim, phi_hit);
    }

    int halves(const OrbitPoint& a, const OrbitPoint& b, int depth, const int* cand, int nc, int& prim,
               double& phi_hit) const {
      const OrbitPoint mid = at(0.5 * (a.phi + b.phi));
      if (!std::isfinite(mid.u)) return -1;
      const int left = piece(a, mid, depth + 1, cand, nc, prim, phi_hit);
      if (left != 0) return left;
      return piece(mid, b, depth + 1, cand, nc, prim, phi_hit);
    }
  };

  // A hit on primitive p at orbit point h of walk w (impact parameter b): its position and travel direction in the
  // static frame, b (-u' r + u sqrt(A) phi), A = 1 - 2M u (a unit vector: u'^2 + u^2 A = 1 / b^2).
  void hit(const Walk& w, double b, int p, const OrbitPoint& h, OrbitEnd& e) const {
    double c, s;
    sin_cos(h.phi, s, c);
    const V3 radial = w.e1 * c + w.e2 * s, tangent = w.e2 * c - w.e1 * s;
    e.status = kHit;
    e.prim = p;
    e.pos = h.x;
    e.dir = normalize(radial * (-h.du * b) + tangent * (h.u * std::sqrt(1.0 - 2.0 * mass_ * h.u) * b));
  }

  // An aimed segment (a light sample's): where the orbit passes the aimed point (at the azimuth nearest the image's
  // sweep at which the point lies; within 1e-5 of its distance, the segment's start being a hair off the vertex the
  // image was solved from), the light's plane is crossed there, found by one Taylor step from that azimuth; the
  // orbit is searched for surfaces only up to just before that crossing (1e-9 of its sweep), the aimed light
  // included (the ray may cross it elsewhere first), and if nothing is met it ends at the crossing on the aimed
  // primitive. So the part past the light, the azimuth where the orbit leaves the scene (one R_F) and the search
  // for the light's own crossing (~2.3 orbit evaluations) are not computed. The orbit stays inside the scene all
  // the way: u rises to the periapsis and falls after it (or rises until the ray falls in), so an orbit that starts
  // inside and reaches a point inside never left. False (traced as unaimed): the orbit misses the point, the start
  // is outside the scene, the light is not planar, or the crossing lies off its edge.
  bool aimed(const Walk& w, double b, double r0, const OrbitAim& aim, OrbitEnd& e) const {
    if (!(aim.sweep > 0.0) || !(r0 < sc_.bound_radius)) return false;
    const V3* n = sc_.plane_normal(aim.prim);
    if (!n) return false;
    const double ax = dot(aim.point, w.e1), ay = dot(aim.point, w.e2);
    const double phi_b = aim.sweep + std::remainder(std::atan2(ay, ax) - aim.sweep, kTwoPi);
    if (!(phi_b > 0.0)) return false;
    const typename Walk::Polar q = w.polar(phi_b);
    if (!(std::isfinite(q.u) && q.u > 0.0)) return false;
    const V3 xb = q.x();
    const double reach = length(aim.point - w.x0);
    if (!(length(xb - aim.point) <= 1e-5 * (1.0 + reach))) return false;
    const typename Walk::TaylorRoot tr = w.taylor_root(q, *n, sc_.implicit_at(aim.prim, xb));
    if (!(tr.df != 0.0 && tr.error <= 1e-12 * (1.0 + length(w.x0) + reach))) return false;
    if (!w.within(aim.prim, *n, tr.x)) return false;  // (off the light's edge)
    const double phi_x = phi_b + tr.step;
    const OrbitPoint a = w.at(0.0), z = w.at(phi_x * (1.0 - 1e-9));
    int prim = -1;
    double phi_hit = 0.0;
    if (!(std::isfinite(a.u) && std::isfinite(z.u)) || w.piece(a, z, 0, nullptr, 0, prim, phi_hit) < 0) return false;
    if (prim >= 0) {
      hit(w, b, prim, w.at(phi_hit), e);
      return true;
    }
    // the crossing: u and u' there from the orbit's Taylor expansion about phi_b (the step is ~1e-7)
    const double s = tr.step, ddu = w.orb.ddu(q.u);
    OrbitPoint h;
    h.phi = phi_x;
    h.u = q.u + s * (q.du + 0.5 * s * ddu);
    h.du = q.du + s * (ddu + 0.5 * s * w.orb.dddu(q.u, q.du));
    h.x = tr.x;
    hit(w, b, aim.prim, h, e);
    return true;
  }

  const Scene& sc_;
  double chord_tol_, escape_radius_;
  double mass_ = 0.0, capture_ = 0.0;
};

}  // namespace wv
