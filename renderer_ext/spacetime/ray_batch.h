// Tracing rays in SIMD batches: kLanes rays step together through one Dormand-Prince stepper whose
// values are lane vectors (core/simd.h), so the metric's Hamilton equations and the stage arithmetic
// run for kLanes rays at once. Each lane keeps its own step size; accepting or rejecting a step,
// crossings, monitoring and recording stay per ray, in the very GeodesicRay logic that traces a ray on
// its own (geodesic.h), which sees its lane through Dopri5Lane. When a ray ends its lane takes the next
// ray of the block, so lanes stay busy.
//
// Every lane operation is the scalar operation, so a ray's result is bit-identical to tracing it alone
// (tests/test_batch.py), whatever the other lanes hold, the thread count or the instruction set.
#pragma once

#include <cstddef>
#include <type_traits>
#include <utility>

#include "core/simd.h"
#include "spacetime/geodesic.h"
#include "spacetime/steppers/dopri5.h"

namespace wv {

// Whether metric M can run in lanes: its Hamilton right-hand side is templated over the scalar type.
template <class M, class = void>
struct HasLaneRhs : std::false_type {};
template <class M>
struct HasLaneRhs<M, std::void_t<decltype(std::declval<const M&>().rhs(std::declval<const Lanes*>(),
                                                                        std::declval<Lanes*>()))>>
    : std::true_type {};

// One trial step of every lane; compiled for AVX-512, AVX2 and baseline x86-64 (chosen at load time).
template <class M>
WV_LANE_CLONES void dopri5_lanes_attempt(const M& m, Dopri5<M, Lanes>& st, const Lanes* y, const Lanes* h, double tol,
                                         Lanes* ynew, Lanes* err) {
  *err = st.attempt(m, y, *h, tol, ynew);
}

// One lane of a batch stepper seen as a scalar stepper (the interface of steppers/common.h).
template <class M>
struct Dopri5Lane {
  static constexpr bool kAdaptive = Dopri5<M>::kAdaptive;
  static constexpr int kOrder = Dopri5<M>::kOrder;
  Dopri5<M, Lanes>* batch = nullptr;
  int lane = 0;
  double knew[8];

  void init(const M& m, const double y[8]) {
    double k0[8];
    m.rhs(y, k0);
    for (int i = 0; i < 8; ++i) batch->k[0][i][lane] = k0[i];
  }
  const double* derivative_new() {
    for (int i = 0; i < 8; ++i) knew[i] = batch->k[6][i][lane];
    return knew;
  }
  void accept() {
    for (int i = 0; i < 8; ++i) batch->k[0][i][lane] = batch->k[6][i][lane];
  }
  Dopri5<M> gather() const {
    Dopri5<M> s;
    for (int j = 0; j < 7; ++j)
      for (int i = 0; i < 8; ++i) s.k[j][i] = batch->k[j][i][lane];
    return s;
  }
  void dense(const double y[8], const double ynew[8], double h, double theta, double out[8]) const {
    gather().dense(y, ynew, h, theta, out);
  }
  // A partial step (to a crossing) overwrites the lane's stages, as it does a scalar stepper's.
  double attempt(const M& m, const double y[8], double h, double tol, double ynew[8]) {
    Dopri5<M> s = gather();
    const double e = s.attempt(m, y, h, tol, ynew);
    for (int j = 0; j < 7; ++j)
      for (int i = 0; i < 8; ++i) batch->k[j][i][lane] = s.k[j][i];
    return e;
  }
};

// Traces rays [first, last) through kLanes lanes with dopri5. setup(i, y, sheet) writes ray i's initial
// chart state and sheet (it may throw), track_of(i) is its Track or nullptr, done(i, result) takes
// each finished ray.
template <class M, class Setup, class TrackOf, class Done>
void trace_lanes(const M& m, const TraceOptions& o, std::size_t first, std::size_t last, const Setup& setup,
                 const TrackOf& track_of, const Done& done) {
  using Ray = GeodesicRay<M, Dopri5Lane<M>>;
  Dopri5<M, Lanes> st;
  Lanes y[8], h, ynew[8], err;
  Ray ray[kLanes];
  RayResult res[kLanes];
  Dopri5Lane<M> view[kLanes];
  std::size_t id[kLanes];
  bool active[kLanes];
  std::size_t next = first;
  for (int l = 0; l < kLanes; ++l) {
    view[l].batch = &st;
    view[l].lane = l;
  }
  // Puts the next ray that needs stepping into lane l; false when the block has none left.
  auto fill = [&](int l) {
    while (next < last) {
      const std::size_t i = next++;
      double y0[8];
      int sheet = 1;
      setup(i, y0, sheet);
      res[l] = RayResult();
      if (ray[l].begin(m, y0, sheet, o, res[l], track_of(i)) && ray[l].next()) {
        id[l] = i;
        view[l].init(m, ray[l].y);
        return true;
      }
      done(i, res[l]);
    }
    return false;
  };
  int n_active = 0;
  for (int l = 0; l < kLanes; ++l) n_active += (active[l] = fill(l)) ? 1 : 0;
  while (n_active > 0) {
    int some = 0;
    for (int l = 0; l < kLanes; ++l)
      if (active[l]) {
        some = l;
        for (int i = 0; i < 8; ++i) y[i][l] = ray[l].y[i];
        h[l] = ray[l].h;
      }
    // Idle lanes repeat an active one, so they compute on sane numbers; their results are ignored.
    for (int l = 0; l < kLanes; ++l)
      if (!active[l]) {
        for (int i = 0; i < 8; ++i) {
          y[i][l] = y[i][some];
          st.k[0][i][l] = st.k[0][i][some];
        }
        h[l] = h[some];
      }
    dopri5_lanes_attempt(m, st, y, &h, o.tol, ynew, &err);
    for (int l = 0; l < kLanes; ++l) {
      if (!active[l]) continue;
      double yn[8];
      for (int i = 0; i < 8; ++i) yn[i] = ynew[i][l];
      if (ray[l].advance(view[l], err[l], yn) && ray[l].next()) continue;
      done(id[l], res[l]);
      active[l] = fill(l);
      if (!active[l]) --n_active;
    }
  }
}

}  // namespace wv
