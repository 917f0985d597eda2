// Unidirectional Monte Carlo path tracing along null geodesics, with light connection in curved space.
//
// Camera rays are traced backwards in time (past-directed momentum), so Kerr's frame dragging acts on
// them as on the light that reaches the camera. Each segment of a path is a geodesic from one surface
// to the next (a straight line in flat space, where nothing is integrated). At a diffuse vertex the
// direct light is estimated by two strategies combined with the balance heuristic (multiple importance
// sampling): a BSDF-sampled direction, and a direction towards a light. Where the metric is static and
// spherical the light strategy draws a point on a light and one of its lensed images by the exact lens map
// (lens_connection.h); a light sample then counts only if its geodesic first hits that point, and a BSDF
// direction's light pdf is that of the light point its geodesic first hits, settled after its segment. In
// Kerr the Schwarzschild map does the drawing as a proposal (lens_proposal.h): the pdf is that of where a
// direction's Schwarzschild orbit first crosses the light it hit.
// Elsewhere the direction comes from a proxy (flat-space, pilot-aimed, or Kerr's image proxies:
// light_connection.h) that is a density over directions, and both strategies count whatever emission
// their geodesic reaches first. Either way the weights sum to one for every direction and the estimator
// is unbiased. Camera samples fall at the pixel's stratified points (core/sobol.h) or uniform jitter, and
// with stratified paths each bounce's light point and BSDF direction at a pair of stratified dimensions of its
// own (path_pair). Russian roulette ends long paths. Every random number is a function of (seed, pixel, sample):
// those pairs, and the rest from Rng(seed, pixel, sample). With path
// guiding (guide_tree.h), half of a diffuse vertex's directions come from a tree trained before the render
// (guide_training.h, by this tracer's own paths with a training seed) and the mixture's pdf is the BSDF
// strategy's in every weight.
//
// This file holds the transport of one sample (sample_pixel, pbrt's Li) and the entry point
// path_trace_scene; the pieces it uses are
//   render_loop.h       progressive passes over chunks of pixels, progress, cancellation, film accumulation
//   sample_scheduler.h  samples as coroutines, their geodesics stepped together in SIMD lanes
//   camera.h            the camera's frame and its rays' directions
//   segment.h           tracing one geodesic segment to the next surface or the sky (SegmentEnd)
//   chart_geometry.h    user frame, chart and local observer frame; backward start states
//   emission.h          emitted radiance with redshift and beaming
//   lens_connection.h   the lens-aware light strategy of static spherical metrics and its pdf
//   camera_connection.h the camera's own light samples, in the pixels where a light's lensed image is small
//   light_connection.h  the light strategy's proxies, aimed by pilot geodesics (Kerr: image proxies)
//   guide_tree.h        path guiding's learned distribution over space and the local sky
//   guide_training.h    its training iterations
//   photon_tracer.h     photons from the lights through mirrors and glass (caustics), photon_map.h their search
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "core/rng.h"
#include "core/sobol.h"
#include "core/task.h"
#include "core/vec3.h"
#include "film/film.h"
#include "film/pixel_filter.h"
#include "integrators/camera.h"
#include "integrators/camera_connection.h"
#include "integrators/chart_geometry.h"
#include "integrators/emission.h"
#include "integrators/guide_training.h"
#include "integrators/guide_tree.h"
#include "integrators/lens_connection.h"
#include "integrators/light_connection.h"
#include "integrators/photon_map.h"
#include "integrators/photon_tracer.h"
#include "integrators/render_loop.h"
#include "integrators/render_types.h"
#include "integrators/sample_scheduler.h"
#include "integrators/segment.h"
#include "scene/light.h"
#include "scene/material.h"
#include "scene/scene.h"
#include "spacetime/geodesic.h"
#include "spacetime/track.h"

namespace wv {

template <class M, class S>
class PathTracer {
 public:
  using Scheduler = SampleScheduler<M, S>;

  // Path guiding (guide_tree.h): the tree that draws half of each diffuse vertex's directions (null: none),
  // and, for a training iteration (guide_training.h), that its paths record what came back along each
  // direction and draw their random numbers from `seed` instead of the render's.
  struct Guiding {
    const GuideTree* tree = nullptr;
    bool train = false;
    uint64_t seed = 0;
  };
  // The share of a guided vertex's directions the tree draws (the rest: the BSDF), as Mueller et al.
  static constexpr double kGuideShare = 0.5;

  // Caustics by photons (photon_tracer.h): the tracer that says which lights send photons, and the current
  // photon pass (its map and radius, replaced between the render loop's sub-passes); null: none.
  struct Caustics {
    const PhotonTracer<M, S>* tracer = nullptr;
    const PhotonPass* pass = nullptr;
  };

  PathTracer(const M& m, const Scene& sc, const RenderOptions& o, Guiding g = {}, Caustics c = {})
      : sc_(sc), o_(o), camera_(m, sc.camera), filter_(o.filter, o.filter_radius), segments_(m, sc, o), lights_(m, sc, o, segments_.options()),
        emission_(m, sc), lens_(m, sc, o.lens_images, o.light_connection == kLensConnection, o.light_margin, true, o.lens_focus),
        camera_lights_(sc, o, camera_, lens_, !g.train), guide_(g.tree),
        train_(g.train), seed_(g.train ? g.seed : o.seed), caustics_(c), point_frames_(point_light_frames(m, sc)),
        pixel_angle_(2.0 * std::tan(sc.camera.fov * M_PI / 360.0) / std::max(1, sc.camera.height)) {
    PathFrames<M> frames;
    if constexpr (!M::kFlat) {
      frames.e[0] = camera_.start();
      frames.n = frames.next = 1;
    }
    camera_step_ = segments_.first_step(sc.camera.position, sc.camera.sheet,
                                        camera_.direction_at(0.5 * sc.camera.width, 0.5 * sc.camera.height), frames);
  }

  // One light path while it is traced: what it has gathered (L, its throughput beta), the BSDF strategy's
  // pending weight, the lens vertex whose pdf the next segment settles, and the bookkeeping around each
  // geodesic segment (recording, steps, drift, failure).
  struct PathState {
    V3 L{0, 0, 0}, beta{1, 1, 1};
    double mis = 1.0;  // weight of emission found by the next segment (BSDF strategy)
    // The lens connection's pdf of a BSDF-sampled direction depends on where it first hits a light, so at
    // a lens vertex the weight is settled after the next segment.
    bool lens_prev = false;
    LensVertex lens_v;
    V3 lens_w;
    double lens_pb = 0.0;
    double light_ref = 0.0;  // the largest lens light sample estimate on the path so far (light_roulette)
    // So is the aimed connection's (the mixture pdf of the last vertex's proxies, kept in the path's Aim),
    // which only emission needs: most BSDF-sampled directions never meet an emitter.
    bool aimed_prev = false;
    V3 aimed_w;
    double aimed_pb = 0.0;
    bool error = false;
    double max_drift = 0.0;
    int64_t steps = 0;
    std::vector<RecordedSegment>* rec = nullptr;  // a recorded pixel's segments
    int px = 0, py = 0, s = 0;
    // Path guiding's training: the path's diffuse vertices, each with the direction it left along, that
    // direction's pdf, the throughput after it, and the radiance that came back along it so far.
    struct GuideVertex {
      GuideRecord rec;
      double pdf;
      V3 beta, L;
    };
    static constexpr int kGuideVertices = 16;
    struct GuidePath {
      std::vector<GuideRecord> lights;  // the path's light samples that brought light
      int n = 0;
      bool last_is_prev = false;  // the last vertex's direction is the segment just traced
      GuideVertex v[kGuideVertices];
      // A contribution x to the path's radiance, arriving through vertices [lo, hi): divided by each one's
      // throughput, it is what came back along that vertex's direction.
      void credit(V3 x, int lo, int hi) {
        for (int j = lo; j < hi; ++j)
          for (int c = 0; c < 3; ++c)
            if (v[j].beta[c] > 0.0) v[j].L[c] += x[c] / v[j].beta[c];
      }
    };
    std::optional<GuidePath> guide;  // training only
    // The light choice of the path's last diffuse vertex (GuideTree::light_select), or null: even.
    const double* select = nullptr;
    // Adds x (the path's throughput times what a light strategy found, MIS-weighted) to L.
    void add(V3 x) {
      L += x;
      if (guide) guide->credit(x, 0, guide->n);
    }
    // Adds the emission the last segment found, beta Le weighted by mis, to L. A training path credits it to
    // the earlier vertices, not to the one whose direction found it: the guide learns the light that arrives
    // indirectly (or through mirrors and glass), the light strategy already finds the lamps. (Learning the
    // lamps too drew directions to them and made fig10d's error 1.48x that of no guiding, against 1.22x:
    // benchmarks/README.md, "Path guiding".)
    void add_emission(V3 le) {
      const V3 x = beta * le * mis;
      L += x;
      if (!guide) return;
      guide->credit(x, 0, guide->last_is_prev ? guide->n - 1 : guide->n);
    }

    // The track to record the next segment into (null: not recorded).
    Track* open() {
      if (!rec) return nullptr;
      rec->emplace_back();
      return &rec->back().track;
    }
    // After a segment: what it was (recorded) and what it cost.
    void close(const SegmentEnd& e, int sh, int bounce, int8_t kind) {
      if (rec) {
        RecordedSegment& r = rec->back();
        r.px = px;
        r.py = py;
        r.sample = s;
        r.bounce = bounce;
        r.kind = kind;
        r.status = int8_t(e.status);
        r.sheet = sh;
      }
      steps += e.steps;
      max_drift = std::max(max_drift, e.drift);
      if (e.status >= kMaxSteps) error = true;
    }
  };

  // Where sample s of pixel (px, py) looks (pbrt's camera sample): the pixel's stratified point or uniform
  // jitter, offset by the filter's importance sample; the filter's weight goes to `weight`.
  V3 camera_direction(int px, int py, size_t pix, int s, Rng& rng, double& weight) const {
    double jx, jy;
    if (o_.pixel_sampler == kSobolPixels) {
      pixel_sample(seed_, pix, uint64_t(s), jx, jy);
    } else {
      jx = rng.uniform();
      jy = rng.uniform();
    }
    return camera_.direction_sample(px, py, jx, jy, filter_, weight);
  }

  // Two uniform numbers for the path's pair of dimensions number `dim`: with stratified paths (the Sobol pixel
  // sampler and o_.stratified_paths), the pair's point for this sample (core/sobol.h, padded_sample; pair 0 is the
  // camera's point), so that a pixel's samples spread their light points and directions over their squares as
  // they spread their camera points over the pixel; else the path's generator's next two.
  void path_pair(const PathState& ps, int dim, Rng& rng, double& u1, double& u2) const {
    if (o_.stratified_paths && o_.pixel_sampler == kSobolPixels) {
      padded_sample(seed_, size_t(ps.py) * sc_.camera.width + size_t(ps.px), uint64_t(dim), uint64_t(ps.s), u1, u2);
    } else {
      u1 = rng.uniform();
      u2 = rng.uniform();
    }
  }
  // The pairs of bounce b (path_pair): its light sample's point, then its BSDF direction (a guided vertex's
  // mixture, and every choice among lobes, lights and images, draw from the path's generator).
  static int light_pair(int bounce) { return 1 + 2 * bounce; }
  static int bsdf_pair(int bounce) { return 2 + 2 * bounce; }

  // The camera's own light sample for sample s of pixel (px, py) (camera_connection.h), from random numbers of
  // its own (the path's are those of a pixel without it): a point on a light, and the ray of each of its images
  // that lands in the pixel traced from the camera; one that hits that light adds its emission weighted by the
  // balance heuristic against the camera ray (CameraConnection::shot_weight). Recorded as light segments.
  // A pixel that draws stars too (a star field's sub-pixel images) draws one of them as well, a direction in its
  // profile, whose images are traced alike and count if they escape along it.
  static constexpr uint64_t kCameraLightSeed = 0x5bd1e9955bd1e995ULL, kCameraStarSeed = 0x94d049bb133111ebULL;
  Task<void> camera_light(int px, int py, size_t pix, int s, PathState& ps, RenderStats& st, Scheduler* sched) const {
    Rng rng(seed_ ^ kCameraLightSeed, pix, uint64_t(s));
    // Three numbers for a light, three for a star: the point on the light (the direction in the star's profile)
    // stratified over the pixel's samples as the camera rays are.
    double u[6];
    u[0] = rng.uniform();
    u[3] = rng.uniform();
    if (o_.pixel_sampler == kSobolPixels) {
      pixel_sample(seed_ ^ kCameraLightSeed, pix, uint64_t(s), u[1], u[2]);
      pixel_sample(seed_ ^ kCameraStarSeed, pix, uint64_t(s), u[4], u[5]);
    } else {
      for (int k : {1, 2, 4, 5}) u[k] = rng.uniform();
    }
    CameraShot shot[2 * LensImages::kMax];
    int n = camera_lights_.draws_lights(px, py) ? camera_lights_.sample(px, py, u[0], u[1], u[2], shot) : 0;
    if (camera_lights_.draws_stars(px, py)) n += camera_lights_.sample_star(px, py, u[3], u[4], u[5], shot + n);
    for (int k = 0; k < n; ++k) {
      PathFrames<M> frames;
      if constexpr (!M::kFlat) {
        frames.e[0] = camera_.start();
        frames.n = frames.next = 1;
      }
      Track* track = ps.open();
      SegmentEnd e;
      co_await segments_.segment(sc_.camera.position, sc_.camera.sheet, shot[k].w, -1, track, st, frames, sched, e);
      ps.close(e, sc_.camera.sheet, 0, kLightSegment);
      const double w = camera_lights_.shot_weight(px, py, shot[k], e);
      if (w > 0.0) ps.add(emission_.emission(e) * w);
    }
  }

  // The light strategy at diffuse vertex e (pbrt's SampleLd): one light, chosen evenly or as the guide's leaf
  // there learnt (ps.select), and a direction to it, its geodesic traced, and what it brings weighted by the
  // balance heuristic against BSDF sampling.
  // With `lens`, a point on the light and one of its lensed images by the exact lens map
  // (lens_connection.h; ps.lens_v keeps the vertex for the BSDF strategy's pdf); else a direction from the
  // light's pilot-aimed proxy (light_connection.h; `aimed` keeps the proxies for the BSDF strategy's pdf).
  // At a guided vertex (guide leaf >= 0) the BSDF strategy is the mixture of the BSDF and the guide.
  Task<void> sample_light(const SegmentEnd& e, const Material& mat, const V3& albedo, const V3& n, const V3& wo,
                          int bounce, bool lens, int leaf, Rng& rng, PathState& ps, Aim& aimed, RenderStats& st,
                          PathFrames<M>& frames, Scheduler* sched) const {
    const SurfacePoint& sp = e.surface;
    if (lens) {
      ps.lens_v = lens_vertex(e);
      // The light's index and, from what is left of the same uniform number, the image's: as many random
      // numbers as the aimed connection draws, so a vanishing mass reproduces its (flat) paths.
      double u3, per;
      const int li = choose_light(ps.select, rng, u3, per);
      double u1, u2;
      path_pair(ps, light_pair(bounce), rng, u1, u2);
      if (li >= int(sc_.lights.size())) {
        co_await sample_point_light(e, mat, albedo, n, wo, bounce, li, per, u3, ps, st, frames, sched);
        co_return;
      }
      V3 wl, target;
      double pl, sweep;
      if (!lens_.sample(ps.lens_v, li, u1, u2, u3, wl, pl, target, sweep, per)) co_return;
      double pb;
      const V3 f = bsdf_eval(mat, albedo, n, wo, wl, pb);
      if (!(max_component(f) > 0.0)) co_return;
      if (leaf >= 0) pb = guided_pdf(leaf, wl, pb);
      double keep;
      if (!light_roulette(ps, li, f, pl + pb, rng, keep)) co_return;
      Track* light_track = ps.open();
      SegmentEnd le;
      // (aimed: a closed-form segment searches the orbit only up to the light point, orbit_segment.h)
      co_await segments_.segment(offset(e.pos, sp.normal, n, wl), e.sheet, wl, e.prim, light_track, st, frames, sched,
                                 le, e.step, OrbitAim{sc_.lights[li], target, sweep});
      ps.close(le, e.sheet, bounce + 1, kLightSegment);
      if (lens_.light_sample_hits(le, sc_.lights[li], target) && !retro_light(gathers(mat), wl, le))
        add_light(ps, e, li, ps.beta * f * emission_.emission(le) * (keep / (pl + pb)));
      co_return;
    }
    co_await lights_.aim(e, sp.normal, wo, st, frames, sched, aimed);
    double u3, per;  // (u3: the image, where a light has several)
    const int li = choose_light(ps.select, rng, u3, per);
    double u1, u2;
    path_pair(ps, light_pair(bounce), rng, u1, u2);
    if (li >= int(sc_.lights.size())) {
      co_await sample_point_light(e, mat, albedo, n, wo, bounce, li, per, u3, ps, st, frames, sched);
      co_return;
    }
    V3 wl;
    if (!lights_.sample(aimed, e, li, u1, u2, u3, wl)) co_return;
    double pb;
    const V3 f = bsdf_eval(mat, albedo, n, wo, wl, pb);
    const double pl = lights_.lights_pdf(aimed, wl, ps.select);
    if (!(max_component(f) > 0.0 && pl > 0.0)) co_return;
    if (leaf >= 0) pb = guided_pdf(leaf, wl, pb);
    Track* light_track = ps.open();
    SegmentEnd le;
    co_await segments_.segment(offset(e.pos, sp.normal, n, wl), e.sheet, wl, e.prim, light_track, st, frames, sched,
                               le, e.step);
    ps.close(le, e.sheet, bounce + 1, kLightSegment);
    if (!retro_light(gathers(mat), wl, le)) add_light(ps, e, li, ps.beta * f * emission_.emission(le) / (pl + pb));
  }

  // Whether a vertex of material mat gathers photons (every diffuse one, in a render with caustic photons).
  bool gathers(const Material& mat) const { return caustics_.pass && mat.kind == MaterialKind::kDiffuse; }

  // Whether the light that segment le, leaving a vertex along direction w, brings there is the retro photons'
  // (photon_tracer.h: a photon light's light the hole turned back) because that vertex gathers them
  // (`gathers`): then neither strategy, light sample nor BSDF sample, brings it.
  bool retro_light(bool gathers, V3 w, const SegmentEnd& le) const {
    return gathers && le.status == kHit && caustics_.tracer->retro_segment(le.prim, w, le.dir);
  }

  // A BSDF sample at a vertex that also drew a light sample reached a light's lit side; pl: the light strategy's pdf
  // of its direction (0: the full-weight samples of RenderStats::unsampled_light_hits).
  static void count_light_hit(RenderStats& st, double pl) {
    ++st.light_hits;
    if (!(pl > 0.0)) ++st.unsampled_light_hits;
  }

  // Russian roulette on a lens light sample before its geodesic is traced (o_.light_roulette > 0): a sample whose
  // contribution as far as it is known before tracing, beta f L_e / (pl + pb) with L_e the light's emission scale
  // (no redshift, no visibility), is below light_roulette times the largest such estimate on this path so far is
  // traced with probability estimate / threshold and its light then weighted by the inverse (keep): unbiased, and
  // the light samples of a path's dim vertices (deep bounces, grazing light, a faint lamp) mostly cost no
  // geodesic. The first sample on a path sets the scale and is always traced.
  bool light_roulette(PathState& ps, int li, V3 f, double pdf, Rng& rng, double& keep) const {
    keep = 1.0;
    if (!(o_.light_roulette > 0.0)) return true;
    const double c = max_component(ps.beta * f) *
                     sc_.materials[sc_.prims[sc_.lights[size_t(li)]].material].emission_scale() / pdf;
    if (!(c > 0.0) || !std::isfinite(c)) return true;
    const double threshold = o_.light_roulette * ps.light_ref;
    ps.light_ref = std::max(ps.light_ref, c);
    if (c >= threshold) return true;
    const double q = c / threshold;
    if (rng.uniform() >= q) return false;
    keep = 1.0 / q;
    return true;
  }

  // The light strategy towards point light li - (area lights) of the scene (chosen with probability 1 / per)
  // from diffuse vertex e. A point light is never hit, so its light comes from this strategy alone, without
  // multiple importance sampling. In flat space: its one direction, I cos / d^2 if nothing is in the way. In a
  // static spherical metric: its lensed images of order < lens_images by the exact lens map (lens_connection.h),
  // one drawn by u in proportion to what it brings; an image brings the irradiance I / |dA_perp / dOmega_A|,
  // the area at the light across the ray (proper, in the light's local frame) per solid angle at the vertex,
  // from the map's Jacobian. It counts if the geodesic traced from the light along that image's direction
  // first meets this vertex (a surface in between: in its shadow). Where the lens map does not reach (within
  // 1.05 x its innermost sphere) a point light sends nothing to the vertex (docs/architecture.md).
  Task<void> sample_point_light(const SegmentEnd& e, const Material& mat, const V3& albedo, const V3& n,
                                const V3& wo, int bounce, int li, double per, double u, PathState& ps,
                                RenderStats& st, PathFrames<M>& frames, Scheduler* sched) const {
    const int k = li - int(sc_.lights.size());
    const PointLight& pl = sc_.point_lights[size_t(k)];
    const PointLightFrame& pf = point_frames_[size_t(k)];
    if (!pf.ok) co_return;
    if constexpr (M::kFlat) {
      (void)u;
      if (pl.sheet != e.sheet) co_return;
      const V3 dv = pl.pos - e.pos;
      const double d2 = dot(dv, dv);
      if (!(d2 > 0.0)) co_return;
      const V3 w = dv / std::sqrt(d2);
      double pb;
      const V3 f = bsdf_eval(mat, albedo, n, wo, w, pb);
      const double share = pl.profile(-dot(w, pf.axis_local));
      if (!(max_component(f) > 0.0 && share > 0.0)) co_return;
      Track* track = ps.open();
      SegmentEnd le;
      const V3 x0 = offset(e.pos, e.surface.normal, n, w);
      co_await segments_.segment(x0, e.sheet, w, e.prim, track, st, frames, sched, le);
      ps.close(le, e.sheet, bounce + 1, kLightSegment);
      if (le.status == kHit && dot(le.pos - x0, le.pos - x0) < d2) co_return;  // in its shadow
      add_light(ps, e, li, ps.beta * f * pl.intensity * (share * per / d2));
    } else if constexpr (M::kStaticSpherical) {
      (void)frames;
      if (!lens_.applies(e)) co_return;
      LensLight b;
      b.pos = pl.pos;
      b.sheet = pl.sheet;
      const LensImageRays rays = lens_image_rays(lens_.lens(), lens_vertex(e), b, lens_.orders());
      V3 brings[LensImages::kMax], q[LensImages::kMax];
      double weight[LensImages::kMax], total = 0.0;
      for (int i = 0; i < rays.n; ++i) {
        const LensImageRay& ir = rays.ray[i];
        weight[i] = 0.0;
        double pb;
        const V3 f = bsdf_eval(mat, albedo, n, wo, ir.w, pb);
        const double spsi = std::sin(ir.r.psi);
        if (!(max_component(f) > 0.0 && spsi > 0.0 && std::isfinite(ir.r.dphi_dpsi))) continue;
        // |dA_B / dOmega_A| across the ray in the user frame, then the light's local frame's area across it.
        const V3 t = ir.t_arr;
        const double jac = lens_area_jacobian(rays, ir, 1.0);
        V3 t1, t2;
        basis_around(t, t1, t2);
        q[i] = normalize(pf.to_local(-t));  // the direction the light leaves along, in its local frame
        const double across = std::fabs(dot(q[i], cross(pf.to_local(t1), pf.to_local(t2))));
        const double E = pl.profile(dot(q[i], pf.axis_local)) / (jac * across);
        if (!(E > 0.0 && std::isfinite(E))) continue;
        brings[i] = f * pl.intensity * E;
        weight[i] = (brings[i].x + brings[i].y + brings[i].z) / 3.0;
        total += weight[i];
      }
      if (!(total > 0.0)) co_return;
      int i = rays.n - 1;
      double acc = 0.0;
      for (int j = 0; j < rays.n; ++j) {
        acc += weight[j];
        if (weight[j] > 0.0 && u * total < acc) {
          i = j;
          break;
        }
      }
      if (!(weight[i] > 0.0)) co_return;
      Track* track = ps.open();
      SegmentEnd le;
      PathFrames<M> from_light;
      co_await segments_.segment(pl.pos, pl.sheet, q[i], -1, track, st, from_light, sched, le);
      ps.close(le, pl.sheet, bounce + 1, kLightSegment);
      if (!(le.status == kHit && le.prim == e.prim && length(le.pos - e.pos) <= 1e-4 * (1.0 + length(e.pos))))
        co_return;  // in its shadow
      add_light(ps, e, li, ps.beta * brings[i] * (total / weight[i] * per));
    } else {  // (refused before any work: render.py)
      (void)e, (void)mat, (void)albedo, (void)n, (void)wo, (void)bounce, (void)per, (void)u, (void)ps, (void)st;
      (void)frames, (void)sched, (void)pl;
    }
  }

  // A light from the scene's list for a light sample: evenly (sel null; as before guiding, bit for bit) or by
  // a guide leaf's probabilities sel; u3 what is left of the uniform number (the image's choice), `per` the
  // reciprocal of the light's probability.
  int choose_light(const double* sel, Rng& rng, double& u3, double& per) const {
    const int nl = sc_.light_count();
    if (!sel) {
      const double ul = rng.uniform() * double(nl);
      const int li = std::min(nl - 1, int(ul));
      u3 = std::min(ul - double(li), 1.0 - 1e-16);
      per = double(nl);
      return li;
    }
    const double u = rng.uniform();
    double before = 0.0;
    int li = nl - 1;
    for (int k = 0; k < nl - 1; ++k) {
      if (u < before + sel[k]) {
        li = k;
        break;
      }
      before += sel[k];
    }
    u3 = std::clamp((u - before) / sel[li], 0.0, 1.0 - 1e-16);
    per = 1.0 / sel[li];
    return li;
  }

  // What a light sample of light li at vertex e brought (the path's throughput times its MIS-weighted
  // estimate), added to the path; a training path also records the estimate, for the leaf's light choice.
  void add_light(PathState& ps, const SegmentEnd& e, int li, V3 x) const {
    ps.add(x);
    if (!ps.guide) return;
    GuideRecord r;
    r.pos = e.pos;
    r.sheet = e.sheet;
    r.normal = e.surface.normal;
    r.light = li;
    double v = 0.0;
    for (int c = 0; c < 3; ++c)
      if (ps.beta[c] > 0.0) v += x[c] / ps.beta[c];
    r.light_value = v / 3.0;
    if (r.light_value > 0.0 && std::isfinite(r.light_value)) ps.guide->lights.push_back(r);
  }

  // The caustic radiance leaving diffuse vertex e towards wo, from the current photon pass (photon_map.h):
  // the flux of the photons within r of it, on the side wo leaves from, that reached it in at most
  // `segments` segments (the path's own budget), over the gather disk's proper area pi r^2 J, times
  // albedo / pi. Before the pass's shrinking factor, r is o.photon_radius pixels' footprint at the camera
  // path's length to here; at the path's `first` diffuse vertex, the larger of that and the distance to the
  // kGatherNeighbours-th nearest such photon (at most kGatherReach footprints): where the photons are sparse
  // (light spread thin through the glass, a large image) the disk widens until it holds a few, where they
  // crowd (the focus) it stays a pixel's size. (Later vertices see the caustic indirectly, blurred anyway; the
  // search at every vertex added 76 % to a 640 x 480 sample of the glass-ball room, at the first 28 %.)
  static constexpr int kGatherNeighbours = 16;
  static constexpr double kGatherReach = 8.0;
  V3 gather_photons(const SegmentEnd& e, V3 albedo, V3 wo, double path_length, int segments, bool first) const {
    const PhotonPass& pass = *caustics_.pass;
    const double footprint = o_.photon_radius * pixel_angle_ * path_length;
    // (a caustic photon came in two segments at least, one the hole turned back in one: retro_photons)
    const int least = caustics_.tracer->retro() ? 1 : 2;
    if (!(footprint > 0.0) || pass.map.size() == 0 || segments < least) return {0, 0, 0};
    const V3 side = e.surface.normal * arrival_side(e);
    auto usable = [&](const Photon& p) { return p.segments <= segments && dot(p.n_in, side) > 0.5; };
    double r;
    V3 flux{0, 0, 0};
    if (first) {
      flux = pass.map.flux_near(e.pos, e.sheet, kGatherNeighbours, footprint, kGatherReach * footprint,
                                std::sqrt(pass.r2_factor), usable, r);
    } else {
      r = footprint * std::sqrt(pass.r2_factor);
      pass.map.for_each_near(e.pos, e.sheet, r, [&](const Photon& p) {
        if (usable(p)) flux += p.power;
      });
    }
    if (!(max_component(flux) > 0.0)) return {0, 0, 0};
    double J = 1.0;  // proper area over user-frame area of the surface here
    if constexpr (!M::kFlat) {
      V3 t, b;
      basis_around(e.surface.normal, t, b);
      J = length(cross(e.to_local(t), e.to_local(b)));
    }
    return albedo * flux / (M_PI * M_PI * r * r * J);
  }

  // The solid-angle pdf of a guided vertex's direction strategy (the guide's share drawn from leaf `leaf`,
  // the rest from the BSDF, whose pdf is pb) at local direction w.
  double guided_pdf(int leaf, V3 w, double pb) const {
    return kGuideShare * guide_->pdf(leaf, w) + (1.0 - kGuideShare) * pb;
  }

  // A direction at a diffuse vertex from the mixture of the guide (leaf `leaf`) and the BSDF, its pdf the
  // mixture's and its weight f |cos| / pdf.
  BsdfSample guided_sample(const Material& mat, V3 albedo, V3 n, V3 wo, int leaf, Rng& rng) const {
    const double uc = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
    if (uc < kGuideShare) {
      BsdfSample b;
      double pg, pb;
      b.wi = guide_->sample(leaf, u1, u2, pg);
      const V3 f = bsdf_eval(mat, albedo, n, wo, b.wi, pb);
      b.pdf = kGuideShare * pg + (1.0 - kGuideShare) * pb;
      b.valid = b.pdf > 0.0 && max_component(f) > 0.0;
      if (b.valid) b.weight = f / b.pdf;
      return b;
    }
    BsdfSample b = bsdf_sample(mat, albedo, n, wo, u1, u2, u3);
    if (!b.valid || b.delta) return b;
    const double p = guided_pdf(leaf, b.wi, b.pdf);
    b.weight = b.weight * (b.pdf / p);
    b.pdf = p;
    return b;
  }

  // One sample of pixel (px, py): a light path traced back from the camera (pbrt's EvaluatePixelSample and
  // Li). Writes the first-hit AOVs to the film (sample 0) and what it adds to the pixel to `out`. Its pieces:
  // camera_direction (where the sample looks), sample_light (the light strategy at a diffuse vertex,
  // pbrt's SampleLd) and, here, the path's segments, emission and BSDF sampling.
  Task<void> sample_pixel(int px, int py, int s, Film& film, SampleOut& out, bool recorded, RenderStats& st,
                          Scheduler* sched) const {
    PathFrames<M> frames;  // curved space: starts of this path's segments, the camera's first
    if constexpr (!M::kFlat) {
      frames.e[0] = camera_.start();
      frames.n = frames.next = 1;
    }
    const Camera& cam = sc_.camera;
    const size_t pix = size_t(py) * cam.width + px;  // the sample's identity in the image, whatever the window
    Rng rng(seed_, pix, uint64_t(s));
    PathState ps;
    if (train_) ps.guide.emplace();
    ps.rec = recorded ? &out.rec : nullptr;
    ps.px = px;
    ps.py = py;
    ps.s = s;
    double filter_weight, energy0;
    V3 d = camera_.start_direction(camera_direction(px, py, pix, s, rng, filter_weight), energy0);
    V3 x = cam.position;
    double g_camera = 1.0;  // nu_camera / nu_seen along the camera ray
    V3 L_own_shift{0, 0, 0};  // what the camera ray sees of emitters that shift their own light
    int sheet = cam.sheet, skip = -1;
    // The denoiser's features: albedo and normal at the first non-specular hit (no random numbers drawn).
    out.albedo = {0, 0, 0};
    out.albedo_normal = {0, 0, 0};
    bool features_done = film.albedo_sum.empty() && film.albedo_normal_sum.empty();
    V3 L_sharp{0, 0, 0};  // ps.L up to and at the first non-specular hit (the emission AOV)
    bool sharp = !film.emission_sum.empty();
    const bool camera_lights = camera_lights_.applies(px, py);  // the camera's own light samples (after the path)
    Aim aimed;  // the light proxies of the path's last diffuse vertex (aimed connection)
    // Caustics by photons: every diffuse vertex gathers them, so the path tracer leaves out the emission of a
    // photon light reached from the last diffuse vertex through specular vertices only (`specular`).
    bool gathered = false, specular = false;
    bool gathering = false;  // the segment leaves a vertex that gathered (retro light is the photons')
    double path_length = 0.0;  // user-frame distance along the path (vertex to vertex): the gather's footprint
    double first_step = camera_step_;  // where a segment's steps start: the camera's, then the last segment's last

    for (int bounce = 0; bounce < o_.max_depth; ++bounce) {
      Track* track = ps.open();
      SegmentEnd e;
      co_await segments_.segment(x, sheet, d, skip, track, st, frames, sched, e, first_step);
      ps.close(e, sheet, bounce, bounce == 0 ? kCameraSegment : kBounceSegment);
      if (caustics_.pass && e.status == kHit) path_length += length(e.pos - x);
      if (bounce == 0) {
        e.energy *= energy0;
        g_camera = e.energy > 0.0 ? 1.0 / e.energy : 0.0;
        if (s == 0) first_hit_aovs(film, film.index(px, py), e);
      }
      const V3 Le = emission_.emission(e);
      if (bounce == 0 && cam.shift != kShiftNone && e.status == kHit &&
          sc_.materials[sc_.prims[e.prim].material].beaming)
        L_own_shift = ps.beta * Le * ps.mis;
      // Light the hole turned back onto the vertex this segment left: the photons' (photon_tracer.h), not MIS's.
      const bool retro = retro_light(gathering, d, e);
      if (ps.lens_prev && !retro) {
        const double pl = e.status == kHit ? lens_.pdf(ps.lens_v, ps.lens_w, e.prim, e.pos, ps.select) : 0.0;
        ps.mis = ps.lens_pb / (ps.lens_pb + pl);
        if (e.status == kHit && max_component(Le) > 0.0) count_light_hit(st, pl);
      } else if (ps.aimed_prev && !retro && max_component(Le) > 0.0) {
        const double pl = lights_.lights_pdf(aimed, ps.aimed_w, ps.select);
        ps.mis = ps.aimed_pb / (ps.aimed_pb + pl);
        if (e.status == kHit) count_light_hit(st, pl);
      }
      // A light seen directly in a pixel where the camera draws light samples of its own: the balance heuristic.
      if (bounce == 0 && camera_lights && max_component(Le) > 0.0) {
        if (e.status == kHit) ps.mis = 1.0 / (1.0 + camera_lights_.rho(px, py, d, e.prim, e.pos));
        if (e.status == kEscaped) ps.mis = 1.0 / (1.0 + camera_lights_.star_rho(px, py, d, e.sheet));
      }
      if (!retro && !(gathered && specular && e.status == kHit && caustics_.tracer->sends_photons(e.prim)))
        ps.add_emission(Le);  // (else a caustic path: the photons')
      if (sharp) L_sharp = ps.L;
      if (e.status != kHit) break;
      const Material& mat = sc_.materials[sc_.prims[e.prim].material];
      specular = mat.is_delta();
      if (!mat.is_delta()) {  // the first non-specular hit ends the emission AOV and gives the features
        sharp = false;
        if (!features_done) {
          features_done = true;
          out.albedo = feature_albedo(mat, e.surface);
          out.albedo_normal = e.surface.normal;
        }
      }
      if (mat.kind == MaterialKind::kEmissive || bounce + 1 >= o_.max_depth) break;
      const SurfacePoint& sp = e.surface;
      const V3 albedo = sc_.albedo(mat, sp), n = e.normal_local, wo = -e.dir;
      gathering = gathers(mat);
      if (gathering) {
        ps.add(ps.beta * gather_photons(e, albedo, wo, path_length, o_.max_depth - (bounce + 1), !gathered));
        gathered = true;
      }
      const bool nee = o_.light_sampling && !mat.is_delta() && sc_.light_count() > 0;
      const bool lens = nee && lens_connection_on(o_) && lens_.applies(e);
      // A diffuse vertex in a part of space where the guide saw light draws half its directions from it.
      // and chooses its lights as the guide learnt there.
      const int space =
          guide_ && mat.kind == MaterialKind::kDiffuse ? guide_->leaf(e.pos, e.sheet, e.surface.normal) : -1;
      const int leaf = space >= 0 && guide_->has_sky(space) ? space : -1;
      ps.select = space >= 0 ? guide_->light_select(space) : nullptr;
      if (nee) co_await sample_light(e, mat, albedo, n, wo, bounce, lens, leaf, rng, ps, aimed, st, frames, sched);
      BsdfSample bs;
      if (leaf >= 0) {
        bs = guided_sample(mat, albedo, n, wo, leaf, rng);
      } else {
        double u1, u2;
        path_pair(ps, bsdf_pair(bounce), rng, u1, u2);
        bs = bsdf_sample(mat, albedo, n, wo, u1, u2, rng.uniform());
      }
      if (ps.guide) ps.guide->last_is_prev = false;
      if (!bs.valid) break;
      ps.beta *= bs.weight;
      ps.mis = 1.0;
      ps.lens_prev = lens;
      ps.aimed_prev = nee && !lens;
      if (lens) {
        ps.lens_w = bs.wi;
        ps.lens_pb = bs.pdf;
      } else if (nee) {
        ps.aimed_w = bs.wi;
        ps.aimed_pb = bs.pdf;
      }
      if (bounce + 1 >= o_.rr_depth) {
        // Survival probability = throughput (pbrt's rule): lossless paths are never cut.
        const double q = std::min(1.0, max_component(ps.beta));
        if (q < 1.0) {
          if (rng.uniform() >= q) break;
          ps.beta = ps.beta / q;
        }
      }
      if (ps.guide && mat.kind == MaterialKind::kDiffuse && ps.guide->n < PathState::kGuideVertices) {
        auto& gv = ps.guide->v[ps.guide->n++];
        gv.rec.pos = e.pos;
        gv.rec.sheet = e.sheet;
        gv.rec.normal = e.surface.normal;
        gv.rec.dir = bs.wi;
        gv.pdf = bs.pdf / std::max(0.0, dot(bs.wi, n));  // (what a diffuse surface wants: L_i cos)
        gv.beta = ps.beta;
        gv.L = {0, 0, 0};
        ps.guide->last_is_prev = true;
      }
      x = offset(e.pos, sp.normal, n, bs.wi);
      sheet = e.sheet;
      first_step = e.step;
      d = bs.wi;
      skip = e.prim;
    }
    if (camera_lights) {  // directly seen light (also the emission AOV's)
      const V3 before = ps.L;
      co_await camera_light(px, py, pix, s, ps, st, sched);
      L_sharp += ps.L - before;
    }
    V3 L = ps.L;
    if (cam.shift != kShiftNone) {  // the camera's own shift, on all it saw but emitters that shift their own
      auto seen = [&](V3 v) {
        return Emission<M>::shifted(v - L_own_shift, g_camera, cam.shift == kShiftColour) + L_own_shift;
      };
      L = seen(L);
      L_sharp = seen(L_sharp);
    }
    if (!finite(L)) {
      L = {0, 0, 0};
      ps.error = true;
    }
    if (!finite(L_sharp)) L_sharp = {0, 0, 0};
    out.L = filter_weight == 1.0 ? L : L * filter_weight;
    out.emission = filter_weight == 1.0 ? L_sharp : L_sharp * filter_weight;
    out.error = ps.error;
    out.steps = ps.steps;
    out.max_drift = ps.max_drift;
    if (ps.guide) {  // a training path's records: what came back along each direction over its pdf
      for (int j = 0; j < ps.guide->n; ++j) {
        const auto& gv = ps.guide->v[j];
        GuideRecord r = gv.rec;
        r.value = (gv.L.x + gv.L.y + gv.L.z) / (3.0 * gv.pdf);
        if (r.value > 0.0 && std::isfinite(r.value)) out.guide.push_back(r);
      }
      out.guide.insert(out.guide.end(), ps.guide->lights.begin(), ps.guide->lights.end());
    }
  }

  // What the camera ray through image point (x, y) (pixel units, no jitter, no filter) sees, for the render
  // loop's probes for the edges of lights and for detail below a pixel (render_loop.h), without random
  // numbers: the ray is followed through mirrors and glass, glass splitting it into its reflected and
  // refracted branch, each with the share of the light its Fresnel factors give it (depth first, reflection
  // first; at most kProbeSpecular specular vertices along a branch and kProbeLeaves branches; a branch whose
  // share falls below kProbeShare is not followed and counts as seeing no emitter). `hit.light`: a signature of
  // the branches that end on an emitter (0: none; each branch named by its reflect/refract choices), or
  // kProbeMixed where some branches end on one and others do not, so that a sample sees the light or not by its
  // Fresnel choices (a lamp reflected in a glass ball, or seen after reflections inside it): such a pixel's
  // emission is noisy however it is covered, and gets the edge samples as an edge pixel does. `hit.shape`: a
  // signature of where every followed branch ends (the user's shape it hits, or how it leaves: escaped on its
  // sheet, captured, failed), so neighbouring probes differ where an outline or an image of one lies between.
  // Where the lights' lensed images fall, for the render loop's edge pixels (render_loop.h, pixel_classes): in a
  // static spherical metric seen by a static camera, points on every light (a grid by area, a sphere's both
  // halves; about kMarkGrid^2 points shared by all lights) are mapped through the exact lens map from the camera
  // (orders 0 to kMarkOrders - 1) into pixels. Returns, for each pixel of the window (X0, Y0, W, H) row by row,
  // the image coordinates (x, y) of the first image point that fell in it, NaN where none did (2 W H values), or
  // nothing where the map does not apply. A thin lensed arc of a light (the sun squeezed against a throat's rim,
  // a lamp round a hole's far side) is narrower than the probes' half-pixel lattice, which misses it; a probe
  // through the point itself finds it (or finds it hidden). Found from the scene alone, so the classes stay
  // independent of the samples.
  static constexpr int kMarkOrders = 2, kMarkGrid = 48;  // (order 2 is a ring ~1/500 of order 1's brightness)
  std::vector<double> light_image_points(int X0, int Y0, int W, int H) const {
    std::vector<double> at;
    if constexpr (M::kStaticSpherical) {
      const SphericalLens& lens = lens_.lens();
      const V3 cam = sc_.camera.position;
      if (!camera_.static_observer() || !(lens.u_inner > 0.0) || !(length(cam) * lens.u_inner > 1.05)) return at;
      LensVertex v;
      v.pos = cam;
      v.sheet = sc_.camera.sheet;
      v.to_local = camera_.to_local();
      v.radial_local = normalize(v.to_local(normalize(cam)));
      at.assign(2 * size_t(W) * H, NAN);
      const int grid = std::max(8, int(kMarkGrid / std::sqrt(double(std::max<size_t>(1, sc_.lights.size())))));
      for (const int p : sc_.lights) {
        const bool sphere = sc_.prims[p].kind == PrimKind::kSphere;
        for (int half = 0; half < (sphere ? 2 : 1); ++half) {
          const V3 from = half == 0 ? cam : sc_.spheres[sc_.prims[p].index].center * 2.0 - cam;
          for (int i = 0; i < grid; ++i)
            for (int j = 0; j < grid; ++j) {
              LightPoint lp;
              if (!sample_light_point(sc_, p, from, (i + 0.5) / grid, (j + 0.5) / grid, lp)) continue;
              const LensLight b{lp.pos, lp.normal, lp.area, sc_.prims[p].sheet, true};
              const LensImageRays rays = lens_image_rays(lens, v, b, kMarkOrders);
              for (int k = 0; k < rays.n; ++k) {
                double x, y;
                if (!camera_.pixel_of(rays.ray[k].w, x, y)) continue;
                const double px = std::floor(x) - X0, py = std::floor(y) - Y0;
                if (!(px >= 0 && py >= 0 && px < W && py < H)) continue;
                const size_t c = size_t(py) * W + size_t(px);
                if (std::isnan(at[2 * c])) {
                  at[2 * c] = x;
                  at[2 * c + 1] = y;
                }
              }
            }
        }
      }
    } else {
      (void)X0, (void)Y0, (void)W, (void)H;
    }
    return at;
  }

  static constexpr int kProbeSpecular = 6, kProbeLeaves = 16;
  static constexpr double kProbeShare = 1e-3;
  Task<void> probe(double x, double y, RenderStats& st, Scheduler* sched, ProbeHit& hit) const {
    struct Branch {
      V3 x, d;
      int sheet, skip, depth;
      uint32_t code;  // 1 followed by the branch's choices, one bit per glass vertex (1: refracted)
      double share;
    };
    Branch todo[kProbeSpecular + 2];  // depth first: at most one pending sibling per level
    int n_todo = 0, leaves = 0;
    bool any = false, all = true;
    uint32_t signature = 0, shape = 0;
    double energy0;
    todo[n_todo++] = {sc_.camera.position, camera_.start_direction(camera_.direction_at(x, y), energy0),
                      sc_.camera.sheet, -1, 0, 1u, 1.0};
    double radiance = 0.0;
    bool captured = false, specular = false;
    auto leaf = [&](bool emits, uint32_t code, uint32_t end) {
      ++leaves;
      any |= emits;
      all &= emits;
      if (emits) signature ^= (code * 2654435761u) & 0x7fffffffu;  // a branch's name, hashed
      shape ^= (code * 2654435761u) ^ ((end + 1u) * 0x9e3779b1u);     // ... with where it ends
    };
    // Where a branch ends: its shape, or how it left (escaped on either sheet, captured, failed).
    auto end_of = [&](const SegmentEnd& e) {
      return e.status == kHit ? 16u + uint32_t(sc_.prims[e.prim].shape) : uint32_t(e.status) * 2u + (e.sheet < 0);
    };
    while (n_todo > 0) {
      const Branch b = todo[--n_todo];
      PathFrames<M> frames;
      if constexpr (!M::kFlat) {
        if (b.depth == 0) {
          frames.e[0] = camera_.start();
          frames.n = frames.next = 1;
        }
      }
      SegmentEnd e;
      co_await segments_.segment(b.x, b.sheet, b.d, b.skip, nullptr, st, frames, sched, e);
      captured |= e.status == kHorizon;
      const Material* mat = e.status == kHit ? &sc_.materials[sc_.prims[e.prim].material] : nullptr;
      const bool delta = mat && !mat->emits() && mat->is_delta();  // a mirror or glass
      specular |= delta;
      if (!(delta && b.depth < kProbeSpecular &&
            leaves + n_todo + 2 <= kProbeLeaves)) {  // an emitter, a non-specular surface, the sky, or the end
        if (mat && mat->emits()) radiance = std::max(radiance, b.share * max_component(emission_.emission(e)));
        leaf(mat && mat->emits(), b.code, end_of(e));
        continue;
      }
      const V3 n = e.normal_local, wo = -e.dir;
      const bool glass = mat->kind == MaterialKind::kGlass;
      double F = 1.0, cos_t;  // a mirror reflects all
      if (glass)
        F = fresnel_dielectric(std::fabs(dot(wo, n)), dot(wo, n) > 0.0 ? mat->ior : 1.0 / mat->ior, cos_t);
      // u3 = 0 reflects; u3 just below 1 refracts where F < 1
      const BsdfSample refl = bsdf_sample(*mat, {1, 1, 1}, n, wo, 0.5, 0.5, 0.0);
      const BsdfSample refr = F < 1.0 ? bsdf_sample(*mat, {1, 1, 1}, n, wo, 0.5, 0.5, std::nextafter(1.0, 0.0))
                                      : BsdfSample{};
      const Branch kids[2] = {  // pushed refraction first: reflection is traced first
          {offset(e.pos, e.surface.normal, n, refr.wi), refr.wi, e.sheet, e.prim, b.depth + 1, (b.code << 1) | 1u,
           b.share * (1.0 - F)},
          {offset(e.pos, e.surface.normal, n, refl.wi), refl.wi, e.sheet, e.prim, b.depth + 1,
           glass ? b.code << 1 : b.code, b.share * F}};
      for (int k = 0; k < 2; ++k) {
        if (!(k == 0 ? refr.valid : refl.valid)) continue;
        if (kids[k].share < kProbeShare)
          leaf(false, kids[k].code, 15u);  // (not followed)
        else
          todo[n_todo++] = kids[k];
      }
    }
    hit.light = any && !all ? kProbeMixed : int32_t(signature);
    hit.shape = shape;
    hit.radiance = float(radiance);
    hit.captured = captured;
    hit.specular = specular;
  }

 private:
  // The albedo feature of a non-specular surface point, in [0, 1]: a diffuse surface's albedo, an emitter's
  // colour (its texture, white without one).
  V3 feature_albedo(const Material& mat, const SurfacePoint& sp) const {
    V3 a = mat.kind == MaterialKind::kEmissive ? (mat.texture >= 0 ? sc_.textures[mat.texture].eval(sp.u, sp.v) : V3{1, 1, 1})
                                               : sc_.albedo(mat, sp);
    for (int c = 0; c < 3; ++c) a[c] = std::min(1.0, std::max(0.0, a[c]));
    return a;
  }

  // The first-hit AOVs the film keeps, from the camera geodesic `e` of sample 0 of film pixel `pix`.
  void first_hit_aovs(Film& film, size_t pix, const SegmentEnd& e) const {
    if (!film.status.empty()) film.status[pix] = float(e.status);
    if (!film.redshift.empty()) {
      double g = (e.status == kHit || e.status == kEscaped) && e.energy > 0.0 ? 1.0 / e.energy : 0.0;
      if (e.status == kHit) g = emission_.shift(e, sc_.materials[sc_.prims[e.prim].material]);
      film.redshift[pix] = float(g);
    }
    if (!film.depth.empty())
      film.depth[pix] = e.status == kHit ? float(length(e.pos - sc_.camera.position)) : INFINITY;
    if (!film.normal.empty() && e.status == kHit)
      for (int c = 0; c < 3; ++c) film.normal[3 * pix + c] = float(e.surface.normal[c]);
  }

  const Scene& sc_;
  const RenderOptions& o_;
  CameraRays<M> camera_;
  PixelFilter filter_;
  SegmentTracer<M, S> segments_;
  LightConnection<M, S> lights_;  // after segments_, whose trace options its pilots start from
  Emission<M> emission_;
  LensConnection<M> lens_;
  CameraConnection<M> camera_lights_;  // the camera's own light samples (after camera_ and lens_, which it uses)
  const GuideTree* guide_;  // path guiding's tree, or null
  bool train_;              // a training iteration's tracer: its paths record for the next tree
  uint64_t seed_;           // the seed of every random number (the render's, or the training iteration's)
  Caustics caustics_;       // photons for caustics, or none
  std::vector<PointLightFrame> point_frames_;  // the local frame at each point light
  double pixel_angle_;      // a pixel's height as an angle (radians, at the image's centre)
  double camera_step_ = 0.0;  // the first step of the camera's central ray (SegmentTracer::first_step)
};

// Renders scene sc through metric M with stepper S (engine/register.h).
template <class M, class S>
RenderResult path_trace_scene(const M& m, const Scene& sc, const RenderOptions& o) {
  // Probing for the edges of lights is wasted where nothing emits (render_loop.h probes for detail anyway).
  const bool emitters = std::any_of(sc.prims.begin(), sc.prims.end(),
                                    [&sc](const Prim& p) { return sc.materials[p.material].emits(); });
  // Path guiding: the tree an earlier range trained, or trained here before the first sample (guide_training.h).
  std::shared_ptr<const GuideTree> guide = o.guide;
  RenderStats training;
  if (!guide && o.guide_training > 0 && (emitters || !sc.point_lights.empty())) {
    using Tracer = PathTracer<M, S>;
    auto make = [&](const GuideTree* prev, uint64_t seed) {
      return std::make_unique<Tracer>(m, sc, o, typename Tracer::Guiding{prev, true, seed});
    };
    const std::function<bool()> poll = o.poll ? std::function<bool()>([&o] { return o.poll(0, 1); })
                                              : std::function<bool()>();
    auto trained = std::make_shared<GuideTree>();
    train_guide<M, S>(m, sc.camera, o, sc.bvh.bounds(), sc.light_count(), make, poll, *trained, training);
    guide = std::move(trained);
  }
  // Caustics by photons: a photon pass per sample index, built by the render loop before the samples that
  // gather from it (render_loop.h).
  std::unique_ptr<PhotonTracer<M, S>> photons;
  PhotonPass pass;
  RenderStats photon_stats;
  int64_t photon_passes = 0, photons_stored = 0;
  std::function<bool(int64_t)> photon_pass;
  if (o.photons > 0) {
    photons = std::make_unique<PhotonTracer<M, S>>(m, sc, o);
    photon_stats.add(photons->aim_stats());
    if (photons->any_light()) {
      photon_pass = [&, built = int64_t(-1)](int64_t j) mutable {
        if (j == built) return true;
        const std::function<bool()> poll = o.poll ? std::function<bool()>([&o] { return o.poll(0, 1); })
                                                  : std::function<bool()>();
        if (!photons->pass(j, poll, pass.map, photon_stats)) return false;
        pass.r2_factor = photon_radius_factor(j);
        built = j;
        ++photon_passes;
        photons_stored += int64_t(pass.map.size());
        return true;
      };
    }
  }
  typename PathTracer<M, S>::Caustics caustics;
  if (photon_pass) caustics = {photons.get(), &pass};
  const PathTracer<M, S> pt(m, sc, o, {guide && !guide->empty() ? guide.get() : nullptr, false, 0}, caustics);
  auto sample = [&pt](int px, int py, int s, Film& film, SampleOut& out, bool recorded, RenderStats& st,
                      SampleScheduler<M, S>* sched) {
    return pt.sample_pixel(px, py, s, film, out, recorded, st, sched);
  };
  auto probe = [&pt](double x, double y, RenderStats& st, SampleScheduler<M, S>* sched, ProbeHit& hit) {
    return pt.probe(x, y, st, sched, hit);
  };
  auto images = [&pt](int X0, int Y0, int W, int H) { return pt.light_image_points(X0, Y0, W, H); };
  // The radiance from which a light's edge is a bright one (render_types.h: kBrightEdgePixel): kBrightEdgeRatio
  // times the faintest emitter's (Material::emission_scale, as its light's power counts it).
  double faintest = INFINITY;
  for (const Prim& p : sc.prims) {
    const Material& mat = sc.materials[p.material];
    if (!mat.emits()) continue;
    if (mat.emission_scale() > 0.0) faintest = std::min(faintest, mat.emission_scale());
  }
  const double bright = std::isfinite(faintest) ? kBrightEdgeRatio * faintest : INFINITY;
  RenderResult r = render_passes<M, S>(m, sc.camera, o, sample, probe, emitters, photon_pass, images, bright);
  r.guide = guide;
  if (photons) r.photon_aim = photons->aim();
  r.guide_segments = training.segments;
  r.stats.segments += training.segments + photon_stats.segments;
  r.stats.steps += training.steps + photon_stats.steps;
  r.photon_segments = photon_stats.segments;
  r.photon_passes = photon_passes;
  r.photons_stored = photons_stored;
  return r;
}

}  // namespace wv
