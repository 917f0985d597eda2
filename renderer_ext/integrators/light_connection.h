// The light strategy's geometry at a diffuse vertex: where each light's flat-space proxy (scene/light.h) is
// seen from, found in curved space by pilot geodesics aimed at the light's plane (light_aim.h), how much a
// quad's or disk's proxy grows by that aim's correction, and the mixture pdf of sampling a direction from
// the proxies.
#pragma once

#include <algorithm>
#include <coroutine>
#include <cstddef>

#include "core/task.h"
#include "core/vec3.h"
#include "integrators/chart_geometry.h"
#include "integrators/light_aim.h"
#include "integrators/render_types.h"
#include "integrators/sample_scheduler.h"
#include "integrators/segment.h"
#include "scene/light.h"
#include "scene/scene.h"
#include "spacetime/geodesic.h"

namespace wv {

// Where the light proxies are seen from at a vertex: x shifted by each light's pilot miss; and how much
// larger than the light a quad's or disk's proxy is.
inline constexpr int kAimedLights = 8;
struct Aim {
  V3 pos;                   // the vertex
  V3 from[kAimedLights];    // where light i's proxy is seen from (lights past kAimedLights: pos)
  double scale[kAimedLights];  // and its size relative to the light's
  V3 at(size_t i) const { return i < size_t(kAimedLights) ? from[i] : pos; }
  double scale_of(size_t i) const { return i < size_t(kAimedLights) ? scale[i] : 1.0; }
};

template <class M, class S>
class LightConnection {
 public:
  using Scheduler = SampleScheduler<M, S>;

  // Pilots are traced like segments (segment_options), to a looser tolerance.
  LightConnection(const M& m, const Scene& sc, const RenderOptions& o, const TraceOptions& segment_options)
      : m_(m), sc_(sc), o_(o), geo_(m) {
    popt_ = segment_options;
    popt_.tol = std::max(segment_options.tol, o.pilot_tol);
    popt_.max_drift = std::max(segment_options.max_drift, 1e3 * popt_.tol);
  }

  // Where each light's proxy is seen from at vertex e, into a, as an awaitable: pilot geodesics towards
  // the lights in curved space, none in flat space.
  auto aim(const SegmentEnd& e, V3 n_user, V3 wo, RenderStats& st, PathFrames<M>& frames, Scheduler* sched,
           Aim& a) const {
    if constexpr (M::kFlat) {
      (void)n_user;
      (void)wo;
      (void)st;
      (void)frames;
      (void)sched;
      a = unaimed(e);
      return std::suspend_never{};
    } else {
      return pilots(e, n_user, wo, st, frames, sched, a);
    }
  }

  // Mixture pdf of the light strategy for local direction w at a vertex on `sheet`.
  double lights_pdf(const Aim& a, int sheet, const LinearMap& L, V3 w) const {
    double s = 0.0;
    for (size_t i = 0; i < sc_.lights.size(); ++i) {
      const int l = sc_.lights[i];
      if (sc_.prims[l].sheet == sheet) s += light_pdf(sc_, l, a.at(i), L, w, a.scale_of(i));
    }
    return s / double(sc_.lights.size());
  }

 private:
  // Half the diagonal of a quad light, the outer radius of a disk light; 0 for spheres.
  double light_size(int p) const {
    const Prim& pr = sc_.prims[p];
    if (pr.kind == PrimKind::kQuad) return 0.5 * length(sc_.quads[pr.index].eu + sc_.quads[pr.index].ev);
    if (pr.kind == PrimKind::kDisk) return sc_.disks[pr.index].r_out;
    return 0.0;
  }

  // Centre and plane normal of light prim p as aimed at from x.
  void light_target(int p, V3 x, V3& c, V3& nrm) const {
    const Prim& pr = sc_.prims[p];
    if (pr.kind == PrimKind::kQuad) {
      const Quad& q = sc_.quads[pr.index];
      c = q.corner + (q.eu + q.ev) * 0.5;
      nrm = q.normal;
    } else if (pr.kind == PrimKind::kDisk) {
      const Disk& k = sc_.disks[pr.index];
      c = k.center;
      nrm = k.normal;
    } else {
      c = sc_.spheres[pr.index].center;
      nrm = normalize(c - x);
    }
  }

  static Aim unaimed(const SegmentEnd& e) {
    Aim a;
    a.pos = e.pos;
    for (int i = 0; i < kAimedLights; ++i) {
      a.from[i] = e.pos;
      a.scale[i] = 1.0;
    }
    return a;
  }

  // Pilot geodesics from vertex e towards each light, each traced from just off the surface to the
  // light's plane (c, nrm); the proxy is shifted by where they miss.
  Task<void> pilots(const SegmentEnd& e, V3 n_user, V3 wo, RenderStats& st, StartFrames& frames, Scheduler* sched,
                    Aim& a) const {
    a = unaimed(e);
    if (!o_.aim_lights) co_return;
    const int n = std::min<int>(kAimedLights, int(sc_.lights.size()));
    for (int i = 0; i < n; ++i) {
      const int p = sc_.lights[i];
      if (sc_.prims[p].sheet != e.sheet) continue;
      V3 c, nrm;
      light_target(p, e.pos, c, nrm);
      // Fixed-point iteration on the aim point: aim where the last pilot's miss says to.
      V3 target = c;
      for (int it = 0; it < kPilots; ++it) {
        const V3 w0 = normalize(e.to_local(target - e.pos));
        if (dot(w0, e.normal_local) * dot(wo, e.normal_local) <= 0.0) break;  // behind the surface
        double y[8];
        if (!geo_.backward_state(offset(e.pos, n_user, e.normal_local, w0), e.sheet, w0, y, frames)) break;
        const RayResult res = co_await Geodesic<M, S, PlaneTarget<M>>(m_, sched, y, e.sheet, popt_, nullptr,
                                                                      PlaneTarget<M>{m_, c, nrm, e.sheet});
        ++st.segments;
        st.steps += res.n_steps;
        if (res.status != kHit) break;
        V3 miss = V3(res.pos) - c;
        miss = miss - nrm * dot(miss, nrm);
        if (!finite(miss) || length(miss) > 2.0 * length(c - e.pos)) break;
        target = target - miss;
        a.from[i] = e.pos + (c - target);
      }
      // Bending that moves a light's image also stretches it, and what falls outside the proxy is found
      // by BSDF sampling alone (fireflies): the proxy grows by the aim's correction relative to the
      // light's size, at most by half (in Schwarzschild, Kerr and Ellis rooms 14-38 % less noise at
      // equal time, although fewer light samples reach the light; benchmarks/README.md).
      const double size = light_size(p);
      if (o_.light_margin && size > 0.0) a.scale[i] = 1.0 + std::min(0.5, length(target - c) / size);
    }
  }

  static constexpr int kPilots = 2;  // fixed-point iterations of a light's aim point

  const M& m_;
  const Scene& sc_;
  const RenderOptions& o_;
  ChartGeometry<M> geo_;
  TraceOptions popt_;
};

}  // namespace wv
