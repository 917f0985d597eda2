// Geodesic segments of a light path: from the camera or just off a surface to the next surface or the sky,
// a straight line in flat space (one BVH query, nothing integrated), in curved space a backward geodesic
// tested against the scene's surfaces: its exact orbit where the metric has one in closed form
// (orbit_segment.h), else integrated (surface_hits.h); SegmentEnd is where it ended.
#pragma once

#include <algorithm>
#include <coroutine>

#include "core/task.h"
#include "core/vec3.h"
#include "integrators/chart_geometry.h"
#include "integrators/orbit_segment.h"
#include "integrators/render_types.h"
#include "integrators/sample_scheduler.h"
#include "integrators/surface_hits.h"
#include "scene/light.h"
#include "scene/scene.h"
#include "spacetime/frame.h"
#include "spacetime/geodesic.h"
#include "spacetime/track.h"

namespace wv {

// Where a geodesic segment ended.
struct SegmentEnd {
  int status = kNaN;
  int prim = -1;
  V3 pos;          // user frame
  int sheet = 1;
  V3 dir;          // escaped: direction on the sky; hit: local-frame direction of travel at the hit
  double energy = 1.0;  // local energy at the end relative to the camera's (1 / redshift factor)
  SurfacePoint surface;  // hit: user-frame normal and texture coordinates
  V3 normal_local;      // hit: unit normal in the local frame
  LinearMap to_local;   // hit: user-frame displacement -> local frame
  long steps = 0;
  double step = 0.0;    // integrated: the last accepted step, where the next segment from here starts its steps
  double drift = 0.0;
  double y[8];          // hit: chart state (backward momentum)
  ObserverFrame frame;  // hit: the static observer (or ZAMO) there
};

// Which side of hit e's surface the path arrived on: +1 the side its normal points to, -1 behind it. A diffuse
// surface reflects on both sides, so what reaches it is measured from the normal times this.
inline double arrival_side(const SegmentEnd& e) { return dot(e.dir, e.normal_local) <= 0.0 ? 1.0 : -1.0; }

// The ray leaving a surface starts a hair off it, on the side it leaves towards.
inline V3 offset(V3 pos, V3 n_user, V3 n_local, V3 w) {
  const double eps = 1e-7 * (1.0 + length(pos));
  return pos + n_user * (dot(w, n_local) >= 0.0 ? eps : -eps);
}

template <class M, class S>
class SegmentTracer {
 public:
  using Scheduler = SampleScheduler<M, S>;

  // Segments are backward rays, unrecorded, that escape beyond the scene's bounding sphere; with `forward`, light
  // traced forward in time (photons in a spacetime that is not static, where the two differ), always integrated,
  // its energy and direction at the end reported as a backward segment's are.
  SegmentTracer(const M& m, const Scene& sc, const RenderOptions& o, bool forward = false)
      : m_(m), sc_(sc), o_(o), geo_(m), orbits_(m, sc, o.chord_tol, escape_radius(o, sc)), forward_(forward) {
    topt_ = o.trace;
    topt_.record = false;
    topt_.backward = !forward;
    topt_.escape_radius = orbits_.escape_radius();
    closed_form_ = !forward && o.segment_method == kClosedFormSegments && orbits_.active();
  }

  const TraceOptions& options() const { return topt_; }

  // Traces the geodesic segment from user-frame point x on `sheet` along local direction d into e, as an
  // awaitable: done at once in flat space, a coroutine waiting for its geodesic in curved space. An integrated
  // segment attempts first_step first where the caller has one (the SegmentEnd::step of the segment that ended
  // where this one starts, or the camera's first_step below), instead of the largest step allowed, which the
  // error control rejected ~1.2 times per segment (Kerr-Newman room).
  // With an aim (a light sample towards a known point), a closed-form segment searches the orbit only up to
  // that point (OrbitSegments::trace); the end is the same.
  auto segment(V3 x, int sheet, V3 d, int skip, Track* track, RenderStats& st, PathFrames<M>& frames,
               Scheduler* sched, SegmentEnd& e, double first_step = 0.0, OrbitAim aim = {}) const {
    if constexpr (M::kFlat) {
      (void)frames;
      (void)sched;
      (void)aim;
      flat_segment(x, sheet, d, skip, track, st, e);
      return std::suspend_never{};
    } else {
      return curved_segment(x, sheet, d, skip, track, st, frames, sched, e, first_step, aim);
    }
  }

  // The first step the error control accepts on the integrated segment from x along local direction d (at most
  // eight attempts; 0 in flat space or where none is accepted): where segments from x (the camera's) start
  // their steps, instead of from the largest step allowed, which it rejects ~1.3 times per camera segment in
  // the Kerr-Newman room.
  double first_step(V3 x, int sheet, V3 d, PathFrames<M>& frames) const {
    if constexpr (M::kFlat) {
      (void)x, (void)sheet, (void)d, (void)frames;
      return 0.0;
    } else {
      double y[8];
      if (!geo_.backward_state(x, sheet, d, y, frames)) return 0.0;
      TraceOptions t = topt_;
      t.max_steps = 8;
      RayResult res;
      integrate_ray<M, S>(m_, y, sheet, t, res, nullptr);
      return res.first_step;
    }
  }

 private:
  void flat_segment(V3 x, int sheet, V3 d, int skip, Track* track, RenderStats& st, SegmentEnd& e) const {
    ++st.segments;
    SegmentHit hit;
    e.sheet = sheet;
    if (sc_.closest_hit(x, d, 0.0, 1e300, sheet, skip, [x] { return 1e-4 * (1.0 + length(x)); }, hit)) {
      e.status = kHit;
      e.prim = hit.prim;
      e.pos = x + d * hit.t;
      e.dir = d;
      e.surface = sc_.surface(hit.prim, e.pos);
      e.normal_local = e.surface.normal;
    } else {
      e.status = kEscaped;
      e.dir = d;
      e.pos = x + d * topt_.escape_radius;
    }
    if (track) flat_track(x, e.pos, sheet, *track);
    ++st.counts[e.status];
  }

  Task<void> curved_segment(V3 x, int sheet, V3 d, int skip, Track* track, RenderStats& st, StartFrames& frames,
                            Scheduler* sched, SegmentEnd& e, double first_step, OrbitAim aim) const {
    const double skip_dist = 1e-4 * (1.0 + length(x));
    ++st.segments;
    double y[8];
    if (!(forward_ ? geo_.forward_state(x, sheet, d, y, frames) : geo_.backward_state(x, sheet, d, y, frames))) {
      e.status = kHorizon;  // started on or inside the horizon (a surface grazing it)
      ++st.counts[e.status];
      co_return;
    }
    if (closed_form_ && !track && orbit_segment(y, sheet, skip, skip_dist, st, e, aim)) co_return;
    const RayResult res = co_await Geodesic<M, S, SceneSurfaces<M>>(
        m_, sched, y, sheet, topt_, track, SceneSurfaces<M>(m_, sc_, o_.chord_tol, skip, skip_dist), first_step);
    e.status = res.status;
    e.step = res.last_step;
    e.prim = res.prim;
    e.pos = V3(res.pos);
    e.sheet = res.sheet;
    e.steps = res.n_steps;
    for (int k = 0; k < M::kNumInvariants; ++k) e.drift = std::max(e.drift, res.drift[k]);
    st.steps += res.n_steps;
    ++st.counts[e.status];
    if (e.status == kEscaped) {
      e.dir = V3(res.dir);
      e.energy = forward_ ? -res.y[4] : res.y[4];  // p_t of the backward ray = energy measured at rest at infinity
    } else if (e.status == kHit) {
      if (!observer_frame(m_, res.y, e.frame)) {
        e.status = kHorizon;
        co_return;
      }
      finish_hit(res.y, e);
    }
  }

  // The segment from backward state y in closed form (orbit_segment.h); false where it does not apply.
  // A hit's state is rebuilt from the orbit: the local direction of travel there, in the static observer's
  // frame, as a momentum with the start's p_t (conserved); its time coordinate is left at the start's.
  bool orbit_segment(const double y[8], int sheet, int skip, double skip_dist, RenderStats& st, SegmentEnd& e,
                     const OrbitAim& aim) const {
    double dy[8];
    m_.rhs(y, dy);
    OrbitEnd end;
    if (!orbits_.trace(y, dy + 1, sheet, skip, skip_dist, end, aim)) return false;
    e.status = end.status;
    e.prim = end.prim;
    e.pos = end.pos;
    e.sheet = sheet;
    if (e.status == kEscaped) {
      e.dir = end.dir;
      e.energy = y[4];
    } else if (e.status == kHit) {
      StartFrames at;
      double yh[8];
      if (!geo_.backward_state(end.pos, sheet, end.dir, yh, at)) {
        e.status = kHorizon;
      } else {
        const double scale = y[4] / yh[4];
        for (int i = 4; i < 8; ++i) yh[i] *= scale;
        yh[0] = y[0];
        e.frame = at.e[0].f;
        finish_hit(yh, e);
      }
    }
    ++st.counts[e.status];
    return true;
  }

  // A hit at chart state y (backward momentum) with e.frame the observer there: energy, direction, state,
  // surface point and the maps to the local frame.
  void finish_hit(const double* y, SegmentEnd& e) const {
    double n[3];
    e.energy = -momentum_to_frame(e.frame, y + 4, n);
    if (forward_) e.energy = -e.energy;  // (a future-directed momentum: its own energy, its own direction)
    for (int i = 0; i < 8; ++i) e.y[i] = y[i];
    e.dir = V3(n);
    e.surface = sc_.surface(e.prim, e.pos);
    e.normal_local = geo_.local_normal(y, e.frame, e.surface.normal);
    e.to_local = geo_.local_map(y, e.frame);
  }

  static double escape_radius(const RenderOptions& o, const Scene& sc) {
    return std::max(o.trace.escape_radius, 1.05 * sc.bound_radius + 1.0);
  }

  void flat_track(V3 a, V3 b, int sheet, Track& t) const {
    const double L = length(b - a);
    for (int k = 0; k < 2; ++k) {
      const V3 p = k == 0 ? a : b;
      t.xyz.insert(t.xyz.end(), {p.x, p.y, p.z});
      const double lam = k == 0 ? 0.0 : L;
      t.cols.insert(t.cols.end(), {lam, -lam, length(p), lam, 0.0});
      for (int j = 1; j < M::kNumInvariants; ++j) t.cols.insert(t.cols.end(), {0.0, 0.0});  // reported, scaled
      t.cols.push_back(1.0);
      t.cols.push_back(double(sheet));
    }
  }

  const M& m_;
  const Scene& sc_;
  const RenderOptions& o_;
  ChartGeometry<M> geo_;
  OrbitSegments<M> orbits_;
  TraceOptions topt_;
  bool closed_form_ = false;
  bool forward_ = false;
};

}  // namespace wv
