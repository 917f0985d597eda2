// WARPVIZ_REGISTER_METRIC(M): the one line at the end of a metric file (metrics/*.cpp) that enters metric
// M into the registry and instantiates its tracer and renderer.
//
// CMake's warpviz_add_metric compiles a metric file once per stepper, with WARPVIZ_STEPPERS set to that
// stepper's bit (1 rk4, 2 dopri5, 4 dop853), so the three instantiations of the path tracer build in
// parallel and a changed metric rebuilds in a third of the time; the dopri5 compilation also registers
// the metric's facts. Compiled without WARPVIZ_STEPPERS, one file registers everything.
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
#define WARPVIZ_STEPPERS 7
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
  e.relation_problem = &M::param_relation_problem;
  e.make = [](const std::vector<double>& p) -> std::unique_ptr<Spacetime> {
    return std::make_unique<SpacetimeImpl<M>>(M(p));
  };
  return e;
}

template <class M, class S>
StepperEntry stepper_entry(StepperKind kind) {
  StepperEntry e;
  e.metric = M::kName;
  e.stepper = kind;
  e.trace = [](const std::vector<double>& p, const TraceRequest& req) { return trace_bundle<M, S>(M(p), req); };
  e.render = [](const std::vector<double>& p, const Scene& sc, const RenderOptions& o) {
    const M m(p);
    return path_trace_scene<M, S>(m, sc, o);
  };
  return e;
}

// Registers what the steppers in Mask (WARPVIZ_STEPPERS) need; a distinct instantiation per mask, so the
// per-stepper compilations of one metric file never define the same symbol differently.
template <class M, int Mask>
bool register_metric_plugin() {
  static_assert(M::kNumParams == 0 || M::kParams != nullptr, "a metric lists its parameters in kParams");
  if constexpr ((Mask & 2) != 0) register_metric(metric_entry<M>());
  if constexpr ((Mask & 1) != 0) register_stepper(stepper_entry<M, Rk4<M>>(StepperKind::kRk4));
  if constexpr ((Mask & 2) != 0) register_stepper(stepper_entry<M, Dopri5<M>>(StepperKind::kDopri5));
  if constexpr ((Mask & 4) != 0) register_stepper(stepper_entry<M, Dop853<M>>(StepperKind::kDop853));
  return true;
}

}  // namespace wv

#define WARPVIZ_REGISTER_METRIC(M) \
  [[maybe_unused]] static const bool warpviz_registered_##M = ::wv::register_metric_plugin<M, WARPVIZ_STEPPERS>()
