// The light strategy's geometry at a diffuse vertex: where each light's flat-space proxy (scene/light.h) is
// seen from, found in curved space by pilot geodesics aimed at the light's plane (light_aim.h), how much a
// quad's or disk's proxy grows by that aim's correction, and the mixture pdf of sampling a direction from
// the proxies.
//
// Metrics with a lens proxy (Kerr: the Schwarzschild lens map of the same mass, spacetime/lens_map.h) get
// image proxies instead where that map's connection is not their proposal (light_connection "images", lights
// of other shapes, vertices near the hole: lens_connection.h), one per lensed image of a quad or disk light:
// the image of the light's centre in the proxy map (direct, and round the far side of the hole), refined by a
// Newton step on a pilot geodesic with the proxy map's Jacobian, and around it the light's quad (a disk's
// bounding square) mapped into directions by that Jacobian's inverse, enlarged by kImageMargin, sampled
// uniformly on the tangent plane of the image direction. Which image, by its solid angle times cos theta.
// The pdf of any direction is the mixture's, so the estimator stays unbiased whatever Newton finds or
// misses; the centre's direction is moved towards Kerr's by the pilot, the shape is the proxy map's.
#pragma once

#include <algorithm>
#include <coroutine>
#include <cstddef>

#include "core/task.h"
#include "core/vec3.h"
#include "integrators/chart_geometry.h"
#include "integrators/lens_connection.h"
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
inline constexpr int kImageLights = 4;  // lights with image proxies (the rest: aimed proxies)
inline constexpr int kImagesPerLight = 2;

// A lensed image of a light as a parallelogram on the tangent plane of direction w (local frame): the
// points w + x e1 + y e2 with (x, y) = o + s a + r b, (s, r) in [0, 1]^2; area in tangent-plane units.
struct ImageProxy {
  V3 w, e1, e2;
  double o[2], a[2], b[2];
  double area, weight;
};

struct Aim {
  V3 pos;                   // the vertex
  int sheet = 1;            // its sheet
  LinearMap to_local;       // its local frame
  V3 from[kAimedLights];    // where light i's proxy is seen from (lights past kAimedLights: pos)
  double scale[kAimedLights];  // and its size relative to the light's
  int images[kImageLights] = {0, 0, 0, 0};  // light i's image proxies (0: its aimed proxy)
  ImageProxy image[kImageLights][kImagesPerLight];
  double image_total[kImageLights];
  // Light i's aimed proxy (i < kAimedLights, on the vertex's sheet, no image proxies), computed once from
  // from[i], scale[i] and to_local when the aim is done: the light sample and both strategies' pdfs read it.
  LightProxy proxy[kAimedLights];
  int images_of(size_t i) const { return i < size_t(kImageLights) ? images[i] : 0; }
};

template <class M, class S>
class LightConnection {
 public:
  using Scheduler = SampleScheduler<M, S>;

  // Pilots are traced like segments (segment_options), to a looser tolerance.
  LightConnection(const M& m, const Scene& sc, const RenderOptions& o, const TraceOptions& segment_options)
      : m_(m), sc_(sc), o_(o), geo_(m) {
    if constexpr (M::kLensProxy) lens_ = m.lens_proxy();
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
      unaimed(e, a);
      proxies(a);
      return std::suspend_never{};
    } else {
      return pilots(e, n_user, wo, st, frames, sched, a);
    }
  }

  // Mixture pdf of the light strategy for local direction w at the vertex a was aimed from, its lights chosen
  // with probabilities sel (null: evenly).
  double lights_pdf(const Aim& a, V3 w, const double* sel) const {
    double s = 0.0;
    for (size_t i = 0; i < sc_.lights.size(); ++i) {
      const int l = sc_.lights[i];
      const double chosen = sel ? sel[i] : 1.0;  // (times 1: the even choice's sums, bit for bit)
      if (a.images_of(i) > 0) {
        for (int k = 0; k < a.images[i]; ++k)
          s += chosen * (a.image[i][k].weight / a.image_total[i] * image_pdf(a.image[i][k], w));
      } else if (sc_.prims[l].sheet == a.sheet) {
        s += chosen * light_pdf(i < size_t(kAimedLights) ? a.proxy[i] : light_proxy(sc_, l, a.pos, a.to_local), w);
      }
    }
    return sel ? s : s / double(sc_.light_count());  // (point lights: chosen, never hit)
  }

  // A local direction towards light number li from its image proxies (u3 picks the image) or its aimed
  // proxy; false if none.
  bool sample(const Aim& a, const SegmentEnd& e, int li, double u1, double u2, double u3, V3& w) const {
    const int lp = sc_.lights[li];
    if (a.images_of(size_t(li)) > 0) {
      const int n = a.images[li];
      int k = n - 1;
      double acc = 0.0;
      for (int i = 0; i < n; ++i) {
        acc += a.image[li][i].weight;
        if (u3 * a.image_total[li] < acc) {
          k = i;
          break;
        }
      }
      const ImageProxy& p = a.image[li][k];
      const double x = p.o[0] + u1 * p.a[0] + u2 * p.b[0], y = p.o[1] + u1 * p.a[1] + u2 * p.b[1];
      w = normalize(p.w + p.e1 * x + p.e2 * y);
      return true;
    }
    double pdf;
    if (sc_.prims[lp].sheet != e.sheet) return false;
    return li < kAimedLights ? sample_light(a.proxy[li], u1, u2, w, pdf)
                             : sample_light(light_proxy(sc_, lp, a.pos, a.to_local), u1, u2, w, pdf);
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

  static void unaimed(const SegmentEnd& e, Aim& a) {
    a.pos = e.pos;
    a.sheet = e.sheet;
    a.to_local = e.to_local;
    for (int i = 0; i < kAimedLights; ++i) {
      a.from[i] = e.pos;
      a.scale[i] = 1.0;
    }
    for (int i = 0; i < kImageLights; ++i) a.images[i] = 0;
  }

  // The aimed proxies of the first kAimedLights lights, once the aim is done.
  void proxies(Aim& a) const {
    const size_t n = std::min(size_t(kAimedLights), sc_.lights.size());
    for (size_t i = 0; i < n; ++i) {
      const int l = sc_.lights[i];
      if (a.images_of(i) == 0 && sc_.prims[l].sheet == a.sheet)
        light_proxy(sc_, l, a.from[i], a.to_local, a.scale[i], a.proxy[i]);
    }
  }

  // Pilot geodesics from vertex e towards each light, each traced from just off the surface to the
  // light's plane (c, nrm); the proxy is shifted by where they miss.
  Task<void> pilots(const SegmentEnd& e, V3 n_user, V3 wo, RenderStats& st, StartFrames& frames, Scheduler* sched,
                    Aim& a) const {
    unaimed(e, a);
    if (!o_.aim_lights) {
      proxies(a);
      co_return;
    }
    const int n = std::min<int>(kAimedLights, int(sc_.lights.size()));
    for (int i = 0; i < n; ++i) {
      const int p = sc_.lights[i];
      if (sc_.prims[p].sheet != e.sheet) continue;
      if constexpr (M::kLensProxy) {
        if (i < kImageLights && lens_connection_on(o_)) {
          co_await image_proxies(e, n_user, wo, p, st, frames, sched, a, i);
          if (a.images[i] > 0) continue;
        }
      }
      V3 c, nrm;
      light_target(p, e.pos, c, nrm);
      // Fixed-point iteration on the aim point: aim where the last pilot's miss says to.
      V3 target = c;
      for (int it = 0; it < kPilots; ++it) {
        const V3 w0 = normalize(e.to_local(target - e.pos));
        V3 miss;
        bool ok;
        co_await pilot(e, n_user, wo, w0, c, nrm, st, frames, sched, ok, miss);
        if (!ok || length(miss) > 2.0 * length(c - e.pos)) break;
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
    proxies(a);
  }

  // A pilot geodesic from just off vertex e along local direction w to the plane (c, nrm); ok and where it
  // misses c within that plane.
  Task<void> pilot(const SegmentEnd& e, V3 n_user, V3 wo, V3 w, V3 c, V3 nrm, RenderStats& st, StartFrames& frames,
                   Scheduler* sched, bool& ok, V3& miss) const {
    ok = false;
    if (dot(w, e.normal_local) * dot(wo, e.normal_local) <= 0.0) co_return;  // behind the surface
    double y[8];
    if (!geo_.backward_state(offset(e.pos, n_user, e.normal_local, w), e.sheet, w, y, frames)) co_return;
    const RayResult res = co_await Geodesic<M, S, PlaneTarget<M>>(m_, sched, y, e.sheet, popt_, nullptr,
                                                                  PlaneTarget<M>{m_, c, nrm, e.sheet});
    ++st.segments;
    st.steps += res.n_steps;
    if (res.status != kHit) co_return;
    miss = V3(res.pos) - c;
    miss = miss - nrm * dot(miss, nrm);
    ok = finite(miss);
  }

  static constexpr int kPilots = 2;  // fixed-point iterations of a light's aim point
  // Newton iterations of an image's direction, and the image proxies' size relative to the linearised
  // image. Measured in fig10d and fig10e (Kerr a = 0.9, 0.99; 32 x 24, 16 spp): one pilot and 1.6x gave
  // 0.90x the MSE of two pilots and 1.3x, at 0.86x the time; more pilots did not lower the MSE (the
  // Schwarzschild start is already close there), larger or smaller proxies raised it.
  static constexpr int kImagePilots = 1;
  static constexpr double kImageMargin = 1.6;

  // Solid-angle pdf of uniform sampling on image proxy p's parallelogram for local direction w.
  static double image_pdf(const ImageProxy& p, V3 w) {
    const double c = dot(w, p.w);
    if (!(c > 1e-6)) return 0.0;
    const V3 g = w / c - p.w;  // gnomonic projection onto the tangent plane at p.w
    const double x = dot(g, p.e1) - p.o[0], y = dot(g, p.e2) - p.o[1];
    const double det = p.a[0] * p.b[1] - p.a[1] * p.b[0];
    const double s = (x * p.b[1] - y * p.b[0]) / det, r = (p.a[0] * y - p.a[1] * x) / det;
    if (!(s >= 0.0 && s <= 1.0 && r >= 0.0 && r <= 1.0)) return 0.0;
    return 1.0 / (p.area * c * c * c);
  }

  // The image proxies of light prim p (number i) at vertex e: its centre's images in the lens proxy map,
  // each refined by kImagePilots Newton steps on pilot geodesics to the light's plane.
  Task<void> image_proxies(const SegmentEnd& e, V3 n_user, V3 wo, int p, RenderStats& st, StartFrames& frames,
                           Scheduler* sched, Aim& a, int i) const {
    a.images[i] = 0;
    a.image_total[i] = 0.0;
    const Prim& pr = sc_.prims[p];
    if (pr.kind != PrimKind::kQuad && pr.kind != PrimKind::kDisk) co_return;
    if (!(length(e.pos) * lens_.u_inner > 1.3)) co_return;
    V3 c, nrm, eu, ev, corner;
    light_target(p, e.pos, c, nrm);
    if (pr.kind == PrimKind::kQuad) {
      const Quad& q = sc_.quads[pr.index];
      eu = q.eu;
      ev = q.ev;
      corner = q.corner;
    } else {
      const Disk& k = sc_.disks[pr.index];
      eu = k.axis_u * (2.0 * k.r_out);
      ev = k.axis_v * (2.0 * k.r_out);
      corner = k.center - (eu + ev) * 0.5;
    }
    const LensVertex v = lens_vertex(e);
    LensLight b;
    b.pos = c;
    b.normal = nrm;
    b.sheet = pr.sheet;
    b.two_sided = true;
    LensImageFrame fr[LensImages::kMax];
    const int nf = lens_image_frames(lens_, v, b, kImagesPerLight, fr);
    for (int k = 0; k < nf; ++k) {
      LensImageFrame f = fr[k];
      // Least squares of the 3 x 2 Jacobian J = [d_e1 d_e2]: tangent offset = K miss, K = (J^T J)^-1 J^T.
      const double g11 = dot(f.d_e1, f.d_e1), g12 = dot(f.d_e1, f.d_e2), g22 = dot(f.d_e2, f.d_e2);
      const double det = g11 * g22 - g12 * g12;
      if (!(det > 0.0) || !std::isfinite(det)) continue;
      auto tangent = [&](V3 d, double t[2]) {
        const double p1 = dot(f.d_e1, d), p2 = dot(f.d_e2, d);
        t[0] = (g22 * p1 - g12 * p2) / det;
        t[1] = (g11 * p2 - g12 * p1) / det;
      };
      bool ok = true;
      for (int it = 0; it < kImagePilots && ok; ++it) {
        V3 miss;
        co_await pilot(e, n_user, wo, f.w, c, nrm, st, frames, sched, ok, miss);
        if (!ok || length(miss) > 0.5 * length(c - e.pos)) {
          ok = false;
          break;
        }
        double t[2];
        tangent(miss, t);
        const V3 w = normalize(f.w - f.e1 * t[0] - f.e2 * t[1]);
        f.e1 = normalize(f.e1 - w * dot(f.e1, w));
        f.e2 = cross(w, f.e1) * (dot(cross(w, f.e1), f.e2) >= 0.0 ? 1.0 : -1.0);
        f.w = w;
        ok = true;
      }
      if (!ok) continue;
      ImageProxy& ip = a.image[i][a.images[i]];
      ip.w = f.w;
      ip.e1 = f.e1;
      ip.e2 = f.e2;
      double to[2], ta[2], tb[2];
      tangent(corner - c, to);
      tangent(eu, ta);
      tangent(ev, tb);
      for (int j = 0; j < 2; ++j) {
        ip.o[j] = kImageMargin * to[j];
        ip.a[j] = kImageMargin * ta[j];
        ip.b[j] = kImageMargin * tb[j];
      }
      ip.area = std::fabs(ip.a[0] * ip.b[1] - ip.a[1] * ip.b[0]);
      const double cos_a = dot(ip.w, e.normal_local) * arrival_side(e);
      ip.weight = ip.area * std::max(0.0, cos_a);
      if (!(ip.weight > 0.0) || !std::isfinite(ip.weight)) continue;
      a.image_total[i] += ip.weight;
      ++a.images[i];
    }
  }

  const M& m_;
  const Scene& sc_;
  const RenderOptions& o_;
  ChartGeometry<M> geo_;
  TraceOptions popt_;
  SphericalLens lens_;  // metrics with a lens proxy (Kerr): the proxy map
};

}  // namespace wv
