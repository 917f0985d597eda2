// Unidirectional Monte Carlo path tracing along null geodesics, with light connection in curved space.
//
// Camera rays are traced backwards in time (past-directed momentum), so Kerr's frame dragging acts on
// them as on the light that reaches the camera. Each segment of a path is a geodesic from one surface
// to the next (a straight line in flat space, where nothing is integrated). At a diffuse vertex the
// direct light is estimated by two strategies combined with the balance heuristic (multiple importance
// sampling): a BSDF-sampled direction, and a direction towards a light sampled from the light's flat-space
// proxy (scene/light.h). Both directions are traced as geodesics and both count whatever emission their
// geodesic reaches first (a light, the sky, another emitter), so the weights sum to one for every
// direction and the estimator is unbiased even though the proxy ignores bending. Russian roulette ends
// long paths. Every random number comes from Rng(seed, pixel, sample).
//
// A sample is a coroutine that co_awaits each geodesic it needs. In curved space the geodesics of many
// samples wait in a queue and step together in SIMD lanes (spacetime/ray_batch.h); with batch = false
// each is integrated on the spot. Samples' radiance is summed in (pixel, sample) order either way, so the image
// is bit-identical with and without lanes and for any thread count.
#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <coroutine>
#include <cstdint>
#include <deque>
#include <functional>
#include <type_traits>
#include <vector>

#include "core/linalg.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/task.h"
#include "film/film.h"
#include "integrators/render_types.h"
#include "integrators/light_aim.h"
#include "integrators/surface_hits.h"
#include "scene/light.h"
#include "scene/scene.h"
#include "spacetime/frame.h"
#include "spacetime/geodesic.h"
#include "spacetime/ray_batch.h"
#include "spacetime/steppers/common.h"

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
  double drift = 0.0;
  double y[8];          // hit: chart state (backward momentum)
  ObserverFrame frame;  // hit: the static observer (or ZAMO) there
};

template <class M, class S>
class PathTracer {
 public:
  PathTracer(const M& m, const Scene& sc, const RenderOptions& o) : m_(m), sc_(sc), o_(o) {
    topt_ = o.trace;
    topt_.record = false;
    topt_.backward = true;
    topt_.escape_radius = std::max(o.trace.escape_radius, 1.05 * sc.bound_radius + 1.0);
    popt_ = topt_;
    popt_.tol = std::max(topt_.tol, o.pilot_tol);
    popt_.max_drift = std::max(topt_.max_drift, 1e3 * popt_.tol);
  }

  RenderResult render() {
    RenderResult out;
    const Camera& cam = sc_.camera;
    const int W = cam.width, H = cam.height;
    out.film.resize(W, H);
    out.num_columns = track_columns<M>();
    setup_camera();

    // Recorded pixels: slot per pixel (-1 = not recorded).
    std::vector<int> slot(size_t(W) * H, -1);
    std::vector<std::vector<RecordedSegment>> rec;
    for (size_t k = 0; k + 1 < o_.record_pixels.size(); k += 2) {
      const int x = o_.record_pixels[k], y = o_.record_pixels[k + 1];
      if (x < 0 || y < 0 || x >= W || y >= H) continue;
      if (slot[size_t(y) * W + x] < 0) {
        slot[size_t(y) * W + x] = int(rec.size());
        rec.emplace_back();
      }
    }

    // Progressive passes (1, 1, 2, 4, ... samples) so an interrupted render is a whole image.
    std::vector<std::pair<int, int>> passes;
    for (int s0 = 0, n = 1; s0 < o_.spp; s0 += n, n = std::min(2 * n, 64))
      passes.emplace_back(s0, std::min(o_.spp, s0 + n));
    const int64_t total = int64_t(W) * H * o_.spp;
    std::atomic<int64_t> done{0};
    std::atomic<int64_t> counts[6];
    for (auto& c : counts) c = 0;
    std::atomic<int64_t> steps{0}, segments{0};
    const std::function<bool()> poll = o_.poll ? std::function<bool()>([&]() { return o_.poll(done.load(), total); })
                                               : std::function<bool()>();
    const size_t npix = size_t(W) * H;
    constexpr size_t kChunk = 64;  // pixels per parallel task
    const size_t nchunks = (npix + kChunk - 1) / kChunk;
    for (const auto& pass : passes) {
      auto body = [&](size_t c) {
        const size_t p0 = c * kChunk, p1 = std::min(npix, p0 + kChunk);
        const size_t ns = size_t(pass.second - pass.first), njobs = (p1 - p0) * ns;
        std::vector<SampleOut> outs(njobs);
        Stats st;
        auto make = [&](size_t k, Scheduler* sched) {
          const size_t pix = p0 + k / ns;
          return sample_pixel(int(pix % W), int(pix / W), pass.first + int(k % ns), out.film, outs[k],
                              slot[pix] >= 0, st, sched);
        };
        run_samples(njobs, make);
        // Summed in (pixel, sample) order, whatever order the samples finished in.
        for (size_t k = 0; k < njobs; ++k) {
          const size_t pix = p0 + k / ns;
          accumulate(out.film, pix, outs[k]);
          if (slot[pix] >= 0)
            for (auto& seg : outs[k].rec) rec[slot[pix]].push_back(std::move(seg));
        }
        done += int64_t(njobs);
        for (int k = 0; k < 6; ++k)
          if (st.counts[k]) counts[k] += st.counts[k];
        steps += st.steps;
        segments += st.segments;
      };
      if (!parallel_for(nchunks, o_.threads, 1, body, poll)) {
        out.completed = false;
        break;
      }
    }
    for (int k = 0; k < 6; ++k) out.status_counts[k] = counts[k].load();
    out.total_steps = steps.load();
    out.segments = segments.load();
    for (auto& r : rec)
      for (auto& seg : r) out.recorded.push_back(std::move(seg));
    return out;
  }

 private:
  struct Stats {
    int64_t counts[6] = {0, 0, 0, 0, 0, 0};
    int64_t steps = 0, segments = 0;
  };

  // What one sample adds to its pixel (summed later, in sample order).
  struct SampleOut {
    V3 L{0, 0, 0};
    bool error = false;
    double max_drift = 0.0;
    int64_t steps = 0;
    std::vector<RecordedSegment> rec;  // recorded pixels: this sample's segments
  };

  void accumulate(Film& film, size_t pix, const SampleOut& so) const {
    for (int c = 0; c < 3; ++c) film.rgb_sum[3 * pix + c] += so.L[c];
    film.samples[pix] += 1;
    film.steps_sum[pix] += double(so.steps);
    film.max_drift[pix] = std::max(film.max_drift[pix], float(so.max_drift));
    if (so.error) film.errors[pix] += 1;
  }

  // Geodesics step in SIMD lanes in curved space (ray_batch.h), through the batch form of stepper S.
  static constexpr bool kLaned = kLanesFor<M>;
  using Batch = std::conditional_t<kLaned, BatchOf<S>, S>;
  using Job = LaneJob<M, Batch>;

  // Geodesics waiting for a lane, in the order they were asked for.
  struct Scheduler {
    std::deque<Job*> queue;
  };

  // Runs samples make(k, scheduler) for k in [0, n): with lanes, as many at once as keep the lanes busy;
  // otherwise one after another, each geodesic integrated as soon as it is asked for.
  template <class Make>
  void run_samples(size_t n, const Make& make) const {
    if constexpr (kLaned) {
      if (o_.batch) {
        Scheduler sched;
        std::vector<Task<void>> running;
        size_t next = 0;
        auto sweep = [&]() {
          for (size_t i = 0; i < running.size();) {
            if (!running[i].done()) {
              ++i;
              continue;
            }
            running[i].rethrow_if_failed();
            running[i] = std::move(running.back());
            running.pop_back();
          }
        };
        // A lane needs a geodesic: take the oldest waiting one, starting new samples until there is one.
        auto fill = [&](int) -> Job* {
          while (sched.queue.empty() && next < n) {
            sweep();
            Task<void> t = make(next++, &sched);
            t.start();
            if (t.done()) t.rethrow_if_failed();
            else running.push_back(std::move(t));
          }
          if (sched.queue.empty()) return nullptr;
          Job* job = sched.queue.front();
          sched.queue.pop_front();
          return job;
        };
        run_lanes<M, Batch>(m_, fill, [](Job* job, int) { job->waiter.resume(); });
        sweep();
        return;
      }
    }
    for (size_t k = 0; k < n; ++k) {
      Task<void> t = make(k, nullptr);
      t.start();
      t.rethrow_if_failed();
    }
  }

  struct NoLane {};

  // One geodesic to integrate, as an awaitable: queued for a lane (sched non-null) or integrated at once.
  template <class Surf>
  struct Geodesic {
    const M& m;
    Scheduler* sched;
    double y[8];
    int sheet;
    const TraceOptions& o;
    Track* track;
    Surf surf;
    RayResult res;
    std::conditional_t<kLaned, LaneRay<M, Batch, Surf>, NoLane> lane;

    Geodesic(const M& metric, Scheduler* s, const double y0[8], int sh, const TraceOptions& opt, Track* tr, Surf sf)
        : m(metric), sched(s), sheet(sh), o(opt), track(tr), surf(std::move(sf)) {
      for (int i = 0; i < 8; ++i) y[i] = y0[i];
    }
    Geodesic(const Geodesic&) = delete;
    Geodesic& operator=(const Geodesic&) = delete;

    bool await_ready() {
      if constexpr (kLaned) {
        if (sched) return !lane.start(m, y, sheet, o, res, track, &surf);
      }
      integrate_ray<M, S, Surf>(m, y, sheet, o, res, track, &surf);
      return true;
    }
    void await_suspend(std::coroutine_handle<> h) {
      if constexpr (kLaned) {
        lane.waiter = h;
        sched->queue.push_back(&lane);
      }
    }
    RayResult await_resume() const { return res; }
  };

  void setup_camera() {
    const Camera& c = sc_.camera;
    double x4[4];
    if (!m_.user_to_chart(&c.position.x, c.sheet, x4)) throw std::invalid_argument("camera position lies outside the metric's chart");
    if (m_.absorbed(x4)) throw std::invalid_argument("camera position lies inside the horizon");
    ObserverFrame f;
    if (!observer_frame(m_, x4, f)) throw std::invalid_argument("camera position has no static or ZAMO observer");
    const LinearMap L = local_map(x4, f);
    forward_ = normalize(L(c.look_at - c.position));
    V3 up = L(c.up);
    right_ = normalize(cross(forward_, up));
    if (!(length(right_) > 0.5)) throw std::invalid_argument("camera up is parallel to the viewing direction");
    up_ = cross(right_, forward_);
    tan_half_ = std::tan(0.5 * c.fov * M_PI / 180.0);
    camera_start_ = start_frame(c.position, c.sheet);
  }

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
  using PathFrames = std::conditional_t<M::kFlat, NoFrames, StartFrames>;

  typename StartFrames::Entry start_frame(V3 x, int sheet) const {
    typename StartFrames::Entry s;
    s.pos = x;
    s.sheet = sheet;
    s.ok = m_.user_to_chart(&x.x, sheet, s.x4) && observer_frame(m_, s.x4, s.f) && !m_.absorbed(s.x4);
    return s;
  }

  // State of a ray traced backwards from user-frame point x along local direction d: the future-directed
  // momentum of light arriving there along d, negated. False on or inside a horizon.
  bool backward_state(V3 x, int sheet, V3 d, double y[8], StartFrames& frames) const {
    const typename StartFrames::Entry* s = nullptr;
    for (int i = 0; i < frames.n && !s; ++i)
      if (frames.e[i].pos.x == x.x && frames.e[i].pos.y == x.y && frames.e[i].pos.z == x.z && frames.e[i].sheet == sheet)
        s = &frames.e[i];
    if (!s) {
      const int slot = frames.next;
      frames.e[slot] = start_frame(x, sheet);
      frames.next = (slot + 1) % StartFrames::kSize;
      frames.n = std::max(frames.n, slot + 1);
      s = &frames.e[slot];
    }
    if (!s->ok) return false;
    const double minus_d[3] = {-d.x, -d.y, -d.z};
    for (int i = 0; i < 4; ++i) y[i] = s->x4[i];
    frame_to_momentum(s->f, minus_d, y + 4);
    for (int i = 4; i < 8; ++i) y[i] = -y[i];
    return true;
  }

  // Traces the geodesic segment from user-frame point x on `sheet` along local direction d into e, as an
  // awaitable: done at once in flat space, a coroutine waiting for its geodesic in curved space.
  auto segment(V3 x, int sheet, V3 d, int skip, Track* track, Stats& st, PathFrames& frames, Scheduler* sched,
               SegmentEnd& e) const {
    if constexpr (M::kFlat) {
      (void)frames;
      (void)sched;
      flat_segment(x, sheet, d, skip, track, st, e);
      return std::suspend_never{};
    } else {
      return curved_segment(x, sheet, d, skip, track, st, frames, sched, e);
    }
  }

  void flat_segment(V3 x, int sheet, V3 d, int skip, Track* track, Stats& st, SegmentEnd& e) const {
    const double skip_dist = 1e-4 * (1.0 + length(x));
    ++st.segments;
    SegmentHit hit;
    e.sheet = sheet;
    if (sc_.closest_hit(x, d, 0.0, 1e300, sheet, skip, skip_dist, hit)) {
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

  Task<void> curved_segment(V3 x, int sheet, V3 d, int skip, Track* track, Stats& st, StartFrames& frames,
                            Scheduler* sched, SegmentEnd& e) const {
    const double skip_dist = 1e-4 * (1.0 + length(x));
    ++st.segments;
    double y[8];
    if (!backward_state(x, sheet, d, y, frames)) {
      e.status = kHorizon;  // started on or inside the horizon (a surface grazing it)
      ++st.counts[e.status];
      co_return;
    }
    const RayResult res = co_await Geodesic<SceneSurfaces<M>>(
        m_, sched, y, sheet, topt_, track, SceneSurfaces<M>(m_, sc_, o_.chord_tol, skip, skip_dist));
    e.status = res.status;
    e.prim = res.prim;
    e.pos = V3(res.pos);
    e.sheet = res.sheet;
    e.steps = res.n_steps;
    for (int k = 0; k < M::kNumInvariants; ++k) e.drift = std::max(e.drift, res.drift[k]);
    st.steps += res.n_steps;
    ++st.counts[e.status];
    if (e.status == kEscaped) {
      e.dir = V3(res.dir);
      e.energy = res.y[4];  // p_t of the backward ray = energy measured at rest at infinity
    } else if (e.status == kHit) {
      if (!observer_frame(m_, res.y, e.frame)) {
        e.status = kHorizon;
        co_return;
      }
      double n[3];
      e.energy = -momentum_to_frame(e.frame, res.y + 4, n);
      for (int i = 0; i < 8; ++i) e.y[i] = res.y[i];
      e.dir = V3(n);
      e.surface = sc_.surface(e.prim, e.pos);
      e.normal_local = local_normal(res.y, e.frame, e.surface.normal);
      e.to_local = local_map(res.y, e.frame);
    }
  }

  void flat_track(V3 a, V3 b, int sheet, Track& t) const {
    const double L = length(b - a);
    for (int k = 0; k < 2; ++k) {
      const V3 p = k == 0 ? a : b;
      t.xyz.insert(t.xyz.end(), {p.x, p.y, p.z});
      const double lam = k == 0 ? 0.0 : L;
      t.cols.insert(t.cols.end(), {lam, -lam, length(p), lam, 0.0});
      for (int j = 1; j < M::kNumInvariants; ++j) t.cols.push_back(0.0);
      t.cols.push_back(1.0);
      t.cols.push_back(double(sheet));
    }
  }

  // Radiance emitted towards the path by what a segment reached.
  V3 emission(const SegmentEnd& e) const {
    if (e.status == kEscaped) return sc_.sky(e.sheet).radiance(e.dir);
    if (e.status != kHit) return {0, 0, 0};
    const V3 L = sc_.emitted(e.prim, e.surface, e.normal_local, -e.dir);
    const Material& m = sc_.materials[sc_.prims[e.prim].material];
    if (!m.beaming || max_component(L) <= 0.0) return L;
    const double g = shift(e, m);
    if (m.colour_shift) return shifted_colour(L, g);
    return L * (g * g * g * g);  // I_nu / nu^3 is invariant: bolometric radiance goes as g^4
  }

  // Radiance seen in each channel when the source's spectrum is shifted by g: I_nu / nu^3 is invariant,
  // so I_obs(nu) = g^3 I_emit(nu / g). The emitted spectrum is read off the RGB triple as piecewise
  // exponential in frequency through the channels' frequencies (610, 550, 465 nm), continued beyond them
  // with the end segments' slopes (a Wien-like tail), so an exponential spectrum shifts exactly.
  static V3 shifted_colour(V3 L, double g) {
    if (!(g > 0.0)) return {0, 0, 0};
    const double nu[3] = {1.0 / 610.0, 1.0 / 550.0, 1.0 / 465.0};
    const double floor = 1e-6 * std::max(max_component(L), 1e-300);
    const double lg[3] = {std::log(std::max(L.x, floor)), std::log(std::max(L.y, floor)), std::log(std::max(L.z, floor))};
    auto spectrum = [&](double f) {
      const int k = f < nu[1] ? 0 : 1;
      const double t = std::min(50.0, std::max(-50.0, (f - nu[k]) / (nu[k + 1] - nu[k])));
      return std::exp(lg[k] * (1.0 - t) + lg[k + 1] * t);
    };
    const double g3 = g * g * g;
    return {g3 * spectrum(nu[0] / g), g3 * spectrum(nu[1] / g), g3 * spectrum(nu[2] / g)};
  }

  // g = nu_received / nu_emitted for light from the emitter at a hit to the segment's start observer:
  // 1 / (p . u_emitter) with the backward momentum normalised to unit energy at the start.
  double shift(const SegmentEnd& e, const Material& m) const {
    if constexpr (M::kFlat) {
      (void)e;
      (void)m;
      return 1.0;
    } else {
      double E = e.energy;  // static emitter
      if (m.keplerian) {
        const double om = m_.keplerian_omega(e.y);
        const double v[4] = {1.0, -om * e.y[2], om * e.y[1], 0.0};  // d/dt + Omega d/dphi
        double n2 = 0.0;
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b) n2 += e.frame.g[a][b] * v[a] * v[b];
        if (n2 < 0.0) {  // timelike: a circular orbit exists here
          const double s = 1.0 / std::sqrt(-n2);
          E = 0.0;
          for (int a = 0; a < 4; ++a) E += e.y[4 + a] * v[a] * s;
        }
      }
      return E > 0.0 ? 1.0 / E : 0.0;
    }
  }

  // Where the light proxies are seen from at a vertex: x shifted by each light's pilot miss; and how much
  // larger than the light a quad's or disk's proxy is.
  static constexpr int kAimedLights = 8;
  static constexpr int kPilots = 2;
  struct Aim {
    V3 pos;                   // the vertex
    V3 from[kAimedLights];    // where light i's proxy is seen from (lights past kAimedLights: pos)
    double scale[kAimedLights];  // and its size relative to the light's
    V3 at(size_t i) const { return i < size_t(kAimedLights) ? from[i] : pos; }
    double scale_of(size_t i) const { return i < size_t(kAimedLights) ? scale[i] : 1.0; }
  };

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

  // Where each light's proxy is seen from at vertex e, into a, as an awaitable: pilot geodesics towards
  // the lights in curved space, none in flat space.
  auto aim(const SegmentEnd& e, V3 n_user, V3 wo, Stats& st, PathFrames& frames, Scheduler* sched, Aim& a) const {
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
  Task<void> pilots(const SegmentEnd& e, V3 n_user, V3 wo, Stats& st, StartFrames& frames, Scheduler* sched,
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
        if (!backward_state(offset(e.pos, n_user, e.normal_local, w0), e.sheet, w0, y, frames)) break;
        const RayResult res = co_await Geodesic<PlaneTarget<M>>(m_, sched, y, e.sheet, popt_, nullptr,
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

  // Mixture pdf of the light strategy for local direction w at a vertex on `sheet`.
  double lights_pdf(const Aim& a, int sheet, const LinearMap& L, V3 w) const {
    double s = 0.0;
    for (size_t i = 0; i < sc_.lights.size(); ++i) {
      const int l = sc_.lights[i];
      if (sc_.prims[l].sheet == sheet) s += light_pdf(sc_, l, a.at(i), L, w, a.scale_of(i));
    }
    return s / double(sc_.lights.size());
  }

  // The ray leaving a surface starts a hair off it, on the side it leaves towards.
  static V3 offset(V3 pos, V3 n_user, V3 n_local, V3 w) {
    const double eps = 1e-7 * (1.0 + length(pos));
    return pos + n_user * (dot(w, n_local) >= 0.0 ? eps : -eps);
  }

  // One sample of pixel (px, py): a light path traced back from the camera. Writes the first-hit AOVs to
  // the film (sample 0) and what it adds to the pixel to `out`.
  Task<void> sample_pixel(int px, int py, int s, Film& film, SampleOut& out, bool recorded, Stats& st,
                          Scheduler* sched) const {
    std::vector<RecordedSegment>* rec = recorded ? &out.rec : nullptr;
    PathFrames frames;  // curved space: starts of this path's segments, the camera's first
    if constexpr (!M::kFlat) {
      frames.e[0] = camera_start_;
      frames.n = frames.next = 1;
    }
    const Camera& cam = sc_.camera;
    const size_t pix = size_t(py) * cam.width + px;
    Rng rng(o_.seed, pix, uint64_t(s));
    const double aspect = double(cam.width) / cam.height;
    const double sx = (2.0 * (px + rng.uniform()) / cam.width - 1.0) * tan_half_ * aspect;
    const double sy = (1.0 - 2.0 * (py + rng.uniform()) / cam.height) * tan_half_;
    V3 d = normalize(forward_ + right_ * sx + up_ * sy);
    V3 x = cam.position;
    int sheet = cam.sheet, skip = -1;
    V3 L{0, 0, 0}, beta{1, 1, 1};
    double mis = 1.0;  // weight of emission found by the next segment (BSDF strategy)
    bool error = false;
    double max_drift = 0.0;
    int64_t steps = 0;
    // Recording and bookkeeping around each segment.
    auto open = [&]() -> Track* {
      if (!rec) return nullptr;
      rec->emplace_back();
      return &rec->back().track;
    };
    auto close = [&](const SegmentEnd& e, int sh, int bounce, int8_t kind) {
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
    };

    for (int bounce = 0; bounce < o_.max_depth; ++bounce) {
      Track* track = open();
      SegmentEnd e;
      co_await segment(x, sheet, d, skip, track, st, frames, sched, e);
      close(e, sheet, bounce, bounce == 0 ? kCameraSegment : kBounceSegment);
      if (bounce == 0 && s == 0) {
        film.status[pix] = float(e.status);
        double g = (e.status == kHit || e.status == kEscaped) && e.energy > 0.0 ? 1.0 / e.energy : 0.0;
        if (e.status == kHit) g = shift(e, sc_.materials[sc_.prims[e.prim].material]);
        film.redshift[pix] = float(g);
        film.depth[pix] = e.status == kHit ? float(length(e.pos - cam.position)) : INFINITY;
        if (e.status == kHit) {
          for (int c = 0; c < 3; ++c) film.normal[3 * pix + c] = float(e.surface.normal[c]);
        }
      }
      const V3 Le = emission(e);
      L += beta * Le * mis;
      if (e.status != kHit) break;
      const Material& mat = sc_.materials[sc_.prims[e.prim].material];
      if (mat.kind == MaterialKind::kEmissive || bounce + 1 >= o_.max_depth) break;
      const SurfacePoint& sp = e.surface;
      const V3 albedo = sc_.albedo(mat, sp), n = e.normal_local, wo = -e.dir;
      const bool nee = o_.light_sampling && !mat.is_delta() && !sc_.lights.empty();
      Aim aimed;
      if (nee) {
        // Light strategy: a direction from the (pilot-aimed) flat-space proxy of one light, traced as a
        // geodesic.
        co_await aim(e, sp.normal, wo, st, frames, sched, aimed);
        const int li = std::min(int(sc_.lights.size()) - 1, int(rng.uniform() * sc_.lights.size()));
        const double u1 = rng.uniform(), u2 = rng.uniform();
        V3 wl;
        double pl_one;
        const int lp = sc_.lights[li];
        const V3 from = aimed.at(size_t(li));
        if (sc_.prims[lp].sheet == e.sheet &&
            sample_light(sc_, lp, from, e.to_local, u1, u2, wl, pl_one, aimed.scale_of(size_t(li)))) {
          double pb;
          const V3 f = bsdf_eval(mat, albedo, n, wo, wl, pb);
          const double pl = lights_pdf(aimed, e.sheet, e.to_local, wl);
          if (max_component(f) > 0.0 && pl > 0.0) {
            Track* light_track = open();
            SegmentEnd le;
            co_await segment(offset(e.pos, sp.normal, n, wl), e.sheet, wl, e.prim, light_track, st, frames, sched, le);
            close(le, e.sheet, bounce + 1, kLightSegment);
            L += beta * f * emission(le) / (pl + pb);
          }
        }
      }
      const double u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
      const BsdfSample bs = bsdf_sample(mat, albedo, n, wo, u1, u2, u3);
      if (!bs.valid) break;
      beta *= bs.weight;
      mis = 1.0;
      if (nee) {
        const double pl = lights_pdf(aimed, e.sheet, e.to_local, bs.wi);
        mis = bs.pdf / (bs.pdf + pl);
      }
      if (bounce + 1 >= o_.rr_depth) {
        // Survival probability = throughput (pbrt's rule): lossless paths are never cut.
        const double q = std::min(1.0, max_component(beta));
        if (q < 1.0) {
          if (rng.uniform() >= q) break;
          beta = beta / q;
        }
      }
      x = offset(e.pos, sp.normal, n, bs.wi);
      sheet = e.sheet;
      d = bs.wi;
      skip = e.prim;
    }
    if (!finite(L)) {
      L = {0, 0, 0};
      error = true;
    }
    out.L = L;
    out.error = error;
    out.steps = steps;
    out.max_drift = max_drift;
  }

  const M& m_;
  const Scene& sc_;
  const RenderOptions& o_;
  TraceOptions topt_, popt_;  // segments, pilots
  typename StartFrames::Entry camera_start_;
  V3 forward_, right_, up_;
  double tan_half_ = 1.0;
};

template <class M, class S>
RenderResult path_trace_scene(const M& m, const Scene& sc, const RenderOptions& o) {
  PathTracer<M, S> pt(m, sc, o);
  return pt.render();
}

}  // namespace wv
