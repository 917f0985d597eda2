// WARPVIZ_REGISTER_METRIC(M): the one line at the end of a metric file (metrics/*.cpp) that enters metric
// M into the registry and instantiates its tracer and renderer.
//
// WARPVIZ_STEPPERS selects the parts a compilation registers: bit 1 the facts and the three tracers, bits
// 2, 4, 8 the path tracer with rk4, dopri5, dop853. CMake's warpviz_add_metric compiles a metric file
// twice, as 1 | 4 and 2 | 8, so the halves build in parallel (CMakeLists.txt has the timings). Compiled
// without WARPVIZ_STEPPERS, one file registers everything.
#pragma once

#include <iterator>
#include <memory>
#include <vector>

#include "engine/registry.h"
#include "engine/spacetime.h"
#include "integrators/path_tracer.h"
#include "spacetime/bundle.h"
#include "spacetime/ray_batch.h"
#include "spacetime/steppers/dop853.h"
#include "spacetime/steppers/dopri5.h"
#include "spacetime/steppers/rk4.h"

#ifndef WARPVIZ_STEPPERS
#define WARPVIZ_STEPPERS 15
#endif

namespace wv {

template <class M>
MetricEntry metric_entry() {
  MetricEntry e;
  e.name = M::kName;
  e.class_name = M::kClassName;
  e.summary = M::kSummary;
  if constexpr (M::kNumParams > 0) e.params.assign(M::kParams, M::kParams + M::kNumParams);
  e.param_relation = M::kParamRelation;
  e.invariants.assign(M::kInvariantNames, M::kInvariantNames + M::kNumInvariants);
  e.sheets = M::kSheets;
  e.flat = M::kFlat;
  e.lane_rhs = HasLaneRhs<M>::value;
  e.static_spherical = M::kStaticSpherical;
  e.relation_problem = &M::param_relation_problem;
  e.make = [](const std::vector<double>& p) -> std::unique_ptr<Spacetime> {
    return std::make_unique<SpacetimeImpl<M>>(M(p));
  };
  return e;
}

template <class M, class S>
StepperEntry tracer_entry(StepperKind kind) {
  StepperEntry e{M::kName, kind, nullptr, nullptr};
  e.trace = [](const std::vector<double>& p, const TraceRequest& req) { return trace_bundle<M, S>(M(p), req); };
  return e;
}

template <class M, class S>
StepperEntry renderer_entry(StepperKind kind) {
  StepperEntry e{M::kName, kind, nullptr, nullptr};
  e.render = [](const std::vector<double>& p, const Scene& sc, const RenderOptions& o) {
    const M m(p);
    return path_trace_scene<M, S>(m, sc, o);
  };
  return e;
}

// Registers what the parts in Mask (WARPVIZ_STEPPERS) need: bit 1 the metric's facts and its tracers for
// all three steppers, bits 2, 4, 8 its renderer with rk4, dopri5, dop853. A flat metric never steps, so
// one instantiation serves every stepper. A distinct instantiation per mask, so the compilations of one
// metric file never define the same symbol differently.
template <class M, int Mask>
bool register_metric_plugin() {
  static_assert(M::kNumParams == 0 || M::kParams != nullptr, "a metric lists its parameters in kParams");
  constexpr StepperKind kKinds[3] = {StepperKind::kRk4, StepperKind::kDopri5, StepperKind::kDop853};
  if constexpr ((Mask & 1) != 0) {
    register_metric(metric_entry<M>());
    if constexpr (M::kFlat) {
      for (StepperKind k : kKinds) {
        register_stepper(tracer_entry<M, Dopri5<M>>(k));
        register_stepper(renderer_entry<M, Dopri5<M>>(k));
      }
    } else {
      register_stepper(tracer_entry<M, Rk4<M>>(StepperKind::kRk4));
      register_stepper(tracer_entry<M, Dopri5<M>>(StepperKind::kDopri5));
      register_stepper(tracer_entry<M, Dop853<M>>(StepperKind::kDop853));
    }
  }
  if constexpr (!M::kFlat) {
    if constexpr ((Mask & 2) != 0) register_stepper(renderer_entry<M, Rk4<M>>(StepperKind::kRk4));
    if constexpr ((Mask & 4) != 0) register_stepper(renderer_entry<M, Dopri5<M>>(StepperKind::kDopri5));
    if constexpr ((Mask & 8) != 0) register_stepper(renderer_entry<M, Dop853<M>>(StepperKind::kDop853));
  }
  return true;
}

}  // namespace wv

#define WARPVIZ_REGISTER_METRIC(M) \
  [[maybe_unused]] static const bool warpviz_registered_##M = ::wv::register_metric_plugin<M, WARPVIZ_STEPPERS>()
