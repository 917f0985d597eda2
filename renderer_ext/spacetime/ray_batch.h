// Tracing rays in SIMD batches: kLanes rays step together through one stepper (dopri5, dop853 or rk4)
// whose values are lane vectors (core/simd.h), so the metric's Hamilton equations and the stage
// arithmetic run for kLanes rays at once. Each lane keeps its own step size; accepting or rejecting a
// step, crossings, monitoring and recording stay per ray, in the very GeodesicRay logic that traces a
// ray on its own (geodesic.h), which sees its lane through StepperLane. When a ray ends its lane takes the next
// job (run_lanes): the next ray of a trace() block, or the next geodesic that a path tracer's sample
// waits for (integrators/sample_scheduler.h), so lanes stay busy; each job has its own tolerance.
//
// Every lane operation is the scalar operation, so a ray's result is bit-identical to tracing it alone
// (tests/test_batch.py), whatever the other lanes hold, the thread count or the instruction set.
#pragma once

#include <coroutine>
#include <cstddef>
#include <type_traits>
#include <utility>

#include "core/simd.h"
#include "spacetime/geodesic.h"
#include "spacetime/steppers/common.h"
#include "spacetime/steppers/step_control.h"

namespace wv {

// Whether metric M can run in lanes: its Hamilton right-hand side is templated over the scalar type
// (Minkowski never steps).
template <class M, class = void>
struct HasLaneRhs : std::false_type {};
template <class M>
struct HasLaneRhs<M, std::void_t<decltype(std::declval<const M&>().rhs(std::declval<const Lanes*>(),
                                                                        std::declval<Lanes*>()))>>
    : std::true_type {};

// Whether rays of metric M step in lanes (with any stepper), and stepper S's batch form.
template <class M>
constexpr bool kLanesFor = !M::kFlat && HasLaneRhs<M>::value;
template <class S>
using BatchOf = typename S::template Rebind<Lanes>;

// One trial step of every lane of batch stepper B (a stepper over Lanes); compiled for AVX-512, AVX2 and
// baseline x86-64 (chosen at load time).
template <class M, class B>
WV_LANE_CLONES void lanes_attempt(const M& m, B& st, const Lanes* y, const Lanes* h, const Lanes* tol,
                                  const Lanes* log_prev, Lanes* ynew, Lanes* err, StepFactors<Lanes>* f) {
  *err = st.attempt(m, y, *h, *tol, ynew);
  if constexpr (B::kAdaptive) *f = step_factors<B::kOrder>(*err, *log_prev);  // all lanes at once
}

// One lane of batch stepper B seen as a scalar stepper (the interface of steppers/common.h). Dense output
// and partial steps use a scalar copy of the lane's stages, gathered once per batch step.
template <class M, class B>
struct StepperLane {
  using Scalar = typename B::template Rebind<double>;
  static constexpr bool kAdaptive = Scalar::kAdaptive;
  static constexpr bool kAccurateDense = Scalar::kAccurateDense;
  static constexpr int kOrder = Scalar::kOrder;
  static constexpr int kStages = B::kStages, kNew = B::kNew;
  B* batch = nullptr;
  int lane = 0;
  double knew[8];
  mutable Scalar cache;  // the lane's stages, valid while `cached`
  mutable bool cached = false;

  // The batch stepper has made a new trial step.
  void invalidate() { cached = false; }
  void init(const M& m, const double y[8]) {
    double k0[8];
    m.rhs(y, k0);
    for (int i = 0; i < 8; ++i) batch->k[0][i][lane] = k0[i];
    cached = false;
  }
  const double* derivative_new() {
    for (int i = 0; i < 8; ++i) knew[i] = batch->k[kNew][i][lane];
    return knew;
  }
  void accept() {
    for (int i = 0; i < 8; ++i) batch->k[0][i][lane] = batch->k[kNew][i][lane];
    cached = false;
  }
  const Scalar& scalar() const {
    if (!cached) {
      for (int j = 0; j < kStages; ++j)
        for (int i = 0; i < 8; ++i) cache.k[j][i] = batch->k[j][i][lane];
      if constexpr (requires { cache.dense_ready; }) {  // dop853: its dense output's extra stages
        cache.metric = batch->metric;
        cache.dense_ready = false;
      }
      cached = true;
    }
    return cache;
  }
  void dense(const double y[8], const double ynew[8], double h, double theta, double out[8]) const {
    scalar().dense(y, ynew, h, theta, out);
  }
  // From the lane's end-point derivatives only: no gather of its other stages.
  void midpoint(const double y[8], const double ynew[8], double h, double out[8]) const {
    double f0[8], f1[8];
    for (int i = 0; i < 8; ++i) {
      f0[i] = batch->k[0][i][lane];
      f1[i] = batch->k[kNew][i][lane];
    }
    hermite_midpoint(y, f0, ynew, f1, h, out);
  }
  // A partial step (to a crossing) overwrites the lane's stages, as it does a scalar stepper's.
  double attempt(const M& m, const double y[8], double h, double tol, double ynew[8]) {
    scalar();
    const double e = cache.attempt(m, y, h, tol, ynew);
    for (int j = 0; j < kStages; ++j)
      for (int i = 0; i < 8; ++i) batch->k[j][i][lane] = cache.k[j][i];
    return e;
  }
};

// A ray that needs stepping, as the lanes see it: any GeodesicRay (of any surface set) behind one
// interface, plus whoever waits for it (a path tracer's coroutine).
template <class M, class B>
struct LaneJob {
  virtual ~LaneJob() = default;
  // advance() then next() of the ray: false when it has ended.
  virtual bool step(StepperLane<M, B>& st, double err, const StepFactors<double>& f, const double ynew[8]) = 0;
  double* y = nullptr;         // the ray's state to step from
  double* h = nullptr;         // the step to attempt
  double* log_prev = nullptr;  // its step control's log error
  double tol = 1e-9;    // its error tolerance
  std::coroutine_handle<> waiter;
};

template <class M, class B, class Surf = NoSurfaces>
struct LaneRay final : LaneJob<M, B> {
  GeodesicRay<M, StepperLane<M, B>, Surf> ray;
  // Sets the ray up (GeodesicRay::begin and the first next()); false if it has ended already.
  bool start(const M& m, const double y0[8], int sheet, const TraceOptions& o, RayResult& res, Track* track,
             Surf* surfaces = nullptr, double first_step = 0.0) {
    this->y = ray.y;
    this->h = &ray.h;
    this->log_prev = &ray.log_err_prev;
    this->tol = o.tol;
    return ray.begin(m, y0, sheet, o, res, track, surfaces, first_step) && ray.next();
  }
  bool step(StepperLane<M, B>& st, double err, const StepFactors<double>& f, const double ynew[8]) override {
    return ray.advance(st, err, f, ynew) && ray.next();
  }
};

// The lane engine: steps kLanes jobs (each with its own step and tolerance) at a time with batch stepper B
// until fill(lane) has no more. fill(l) returns
// the next job (already started) for lane l or nullptr; done(job, l) is told when a job's ray has ended
// (and may make new jobs for fill to hand out).
template <class M, class B, class Fill, class Done>
void run_lanes(const M& m, const Fill& fill, const Done& done) {
  B st;
  Lanes y[8], h, tol, log_prev, ynew[8], err;
  StepFactors<Lanes> f{};
  StepperLane<M, B> view[kLanes];
  LaneJob<M, B>* job[kLanes];
  int n_active = 0;
  auto refill = [&](int l) {
    job[l] = fill(l);
    if (job[l]) view[l].init(m, job[l]->y);
    return job[l] != nullptr;
  };
  for (int l = 0; l < kLanes; ++l) {
    view[l].batch = &st;
    view[l].lane = l;
    n_active += refill(l) ? 1 : 0;
  }
  while (n_active > 0) {
    int some = 0;
    for (int l = 0; l < kLanes; ++l)
      if (job[l]) {
        some = l;
        for (int i = 0; i < 8; ++i) y[i][l] = job[l]->y[i];
        h[l] = *job[l]->h;
        tol[l] = job[l]->tol;
        log_prev[l] = *job[l]->log_prev;
      }
    // Idle lanes repeat an active one, so they compute on sane numbers; their results are ignored.
    for (int l = 0; l < kLanes; ++l)
      if (!job[l]) {
        for (int i = 0; i < 8; ++i) {
          y[i][l] = y[i][some];
          st.k[0][i][l] = st.k[0][i][some];
        }
        h[l] = h[some];
        tol[l] = tol[some];
        log_prev[l] = log_prev[some];
      }
    lanes_attempt(m, st, y, &h, &tol, &log_prev, ynew, &err, &f);
    for (int l = 0; l < kLanes; ++l) view[l].invalidate();
    for (int l = 0; l < kLanes; ++l) {
      if (!job[l]) continue;
      double yn[8];
      for (int i = 0; i < 8; ++i) yn[i] = ynew[i][l];
      if (job[l]->step(view[l], err[l], {f.log_e[l], f.accept[l], f.reject[l]}, yn)) continue;
      done(job[l], l);
      if (!refill(l)) --n_active;
    }
    // Jobs made by done() may wait while lanes sit idle: give them the idle lanes.
    for (int l = 0; l < kLanes; ++l)
      if (!job[l] && refill(l)) ++n_active;
  }
}

// Traces rays [first, last) through the lanes. setup(i, y, sheet) writes ray i's initial chart state
// and sheet (it may throw), track_of(i) is its Track or nullptr, done(i, result) takes each finished ray.
template <class M, class B, class Setup, class TrackOf, class Done>
void trace_lanes(const M& m, const TraceOptions& o, std::size_t first, std::size_t last, const Setup& setup,
                 const TrackOf& track_of, const Done& done) {
  LaneRay<M, B> ray[kLanes];
  RayResult res[kLanes];
  std::size_t id[kLanes];
  std::size_t next = first;
  auto fill = [&](int l) -> LaneJob<M, B>* {
    while (next < last) {
      const std::size_t i = next++;
      double y0[8];
      int sheet = 1;
      setup(i, y0, sheet);
      res[l] = RayResult();
      if (ray[l].start(m, y0, sheet, o, res[l], track_of(i))) {
        id[l] = i;
        return &ray[l];
      }
      done(i, res[l]);
    }
    return nullptr;
  };
  run_lanes<M, B>(m, fill, [&](LaneJob<M, B>*, int l) { done(id[l], res[l]); });
}

}  // namespace wv
