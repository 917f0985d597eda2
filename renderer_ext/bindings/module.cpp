// Thin Python bindings: arrays in, arrays out. Validation with user-facing messages lives in Python
// (warpviz/trace.py); this layer only checks what would otherwise be undefined behaviour.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/parallel.h"
#include "core/registry.h"

namespace nb = nanobind;
using namespace nb::literals;

namespace {

using F64In = nb::ndarray<const double, nb::c_contig, nb::device::cpu>;
using I32In = nb::ndarray<const int32_t, nb::c_contig, nb::device::cpu>;

template <class T>
nb::object to_numpy(std::vector<T>&& v, std::vector<size_t> shape) {
  if (v.empty()) v.reserve(1);
  auto* heap = new std::vector<T>(std::move(v));
  nb::capsule owner(heap, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
  return nb::cast(nb::ndarray<nb::numpy, T>(heap->data(), shape.size(), shape.data(), owner));
}

wv::StepperKind stepper_kind(const std::string& s) {
  if (s == "rk4") return wv::StepperKind::kRk4;
  if (s == "dopri5") return wv::StepperKind::kDopri5;
  if (s == "dop853") return wv::StepperKind::kDop853;
  throw std::invalid_argument("unknown stepper '" + s + "' (known: rk4, dopri5, dop853)");
}

void check_rows(const F64In& a, size_t n, const char* what) {
  if (a.ndim() != 2 || a.shape(0) != n || a.shape(1) != 3)
    throw std::invalid_argument(std::string(what) + " must have shape (n, 3)");
}

std::vector<double> copy1(const F64In& a, size_t expected, const char* what) {
  if (a.ndim() != 1 || a.shape(0) != expected)
    throw std::invalid_argument(std::string(what) + " must have shape (" + std::to_string(expected) + ",)");
  return std::vector<double>(a.data(), a.data() + expected);
}

nb::dict trace(const std::string& metric, const std::vector<double>& params, F64In origins, F64In directions,
               I32In sheets, double tol, const std::string& stepper, long max_steps, double escape_radius,
               double max_drift, double rk4_step, bool record, int threads) {
  auto st = wv::make_spacetime(metric, params);
  const size_t n = origins.ndim() == 2 ? origins.shape(0) : 0;
  check_rows(origins, n, "origins");
  check_rows(directions, n, "directions");
  if (sheets.ndim() != 1 || sheets.shape(0) != n) throw std::invalid_argument("sheets must have shape (n,)");
  wv::TraceRequest req;
  req.n = n;
  req.origins = origins.data();
  req.directions = directions.data();
  req.sheets = sheets.data();
  req.stepper = stepper_kind(stepper);
  req.threads = threads;
  req.options.tol = tol;
  req.options.max_steps = max_steps;
  req.options.escape_radius = escape_radius;
  req.options.max_drift = max_drift;
  req.options.rk4_step = rk4_step;
  req.options.record = record;
  bool interrupted = false;
  req.poll = [&interrupted]() {
    nb::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) {
      interrupted = true;
      return false;
    }
    return true;
  };
  wv::TraceResult r;
  {
    nb::gil_scoped_release release;
    r = st->trace(req);
  }
  if (interrupted) throw nb::python_error();
  const auto names = st->invariant_names();
  const size_t K = names.size();
  nb::dict out;
  nb::dict drift;
  for (size_t k = 0; k < K; ++k) {
    std::vector<double> col(r.drift.begin() + k * n, r.drift.begin() + (k + 1) * n);
    drift[names[k].c_str()] = to_numpy(std::move(col), {n});
  }
  out["status"] = to_numpy(std::move(r.status), {n});
  out["final_positions"] = to_numpy(std::move(r.final_positions), {n, 3});
  out["final_directions"] = to_numpy(std::move(r.final_directions), {n, 3});
  out["final_sheets"] = to_numpy(std::move(r.final_sheets), {n});
  out["n_steps"] = to_numpy(std::move(r.n_steps), {n});
  out["invariant_drift"] = drift;
  if (record) {
    const size_t P = r.points.size() / 3, C = size_t(r.num_columns);
    out["points"] = to_numpy(std::move(r.points), {P, 3});
    out["offsets"] = to_numpy(std::move(r.offsets), {n + 1});
    out["columns"] = to_numpy(std::move(r.columns), {C, P});
  }
  return out;
}

nb::list metrics() {
  nb::list out;
  for (const auto& e : wv::metric_registry()) {
    nb::dict d;
    d["name"] = e.name;
    d["params"] = e.params;
    d["invariants"] = e.invariants;
    out.append(d);
  }
  return out;
}

}  // namespace

NB_MODULE(_core, m) {
  m.doc() = "warpviz native core: null geodesics of Minkowski, Schwarzschild, Kerr and Ellis spacetimes";
  m.def("metrics", &metrics, "Registered metrics: list of {name, params, invariants}.");
  m.def("trace", &trace, "metric"_a, "params"_a, "origins"_a, "directions"_a, "sheets"_a, "tol"_a, "stepper"_a,
        "max_steps"_a, "escape_radius"_a, "max_drift"_a, "rk4_step"_a, "record"_a, "threads"_a,
        "Trace rays; see warpviz.trace for the documented interface.");
  m.def(
      "inverse_metric",
      [](const std::string& metric, const std::vector<double>& params, F64In x) {
        auto st = wv::make_spacetime(metric, params);
        const auto xv = copy1(x, 4, "x");
        double gi[4][4];
        st->inverse_metric(xv.data(), gi);
        std::vector<double> out(&gi[0][0], &gi[0][0] + 16);
        return to_numpy(std::move(out), {4, 4});
      },
      "metric"_a, "params"_a, "x"_a);
  m.def(
      "rhs",
      [](const std::string& metric, const std::vector<double>& params, F64In y, bool autodiff) {
        auto st = wv::make_spacetime(metric, params);
        const auto yv = copy1(y, 8, "y");
        std::vector<double> dy(8);
        if (autodiff) st->rhs_autodiff(yv.data(), dy.data()); else st->rhs(yv.data(), dy.data());
        return to_numpy(std::move(dy), {8});
      },
      "metric"_a, "params"_a, "y"_a, "autodiff"_a = false);
  m.def(
      "invariants",
      [](const std::string& metric, const std::vector<double>& params, F64In y) {
        auto st = wv::make_spacetime(metric, params);
        const auto yv = copy1(y, 8, "y");
        std::vector<double> out(st->invariant_names().size());
        st->invariants(yv.data(), out.data());
        return to_numpy(std::move(out), {out.size()});
      },
      "metric"_a, "params"_a, "y"_a);
  m.def(
      "initial_state",
      [](const std::string& metric, const std::vector<double>& params, F64In pos, F64In dir, int sheet) {
        auto st = wv::make_spacetime(metric, params);
        const auto p = copy1(pos, 3, "pos"), d = copy1(dir, 3, "dir");
        std::vector<double> y(8);
        if (!st->initial_state(p.data(), d.data(), sheet, y.data()))
          throw std::invalid_argument("position " + st->origin_problem(p.data(), sheet));
        return to_numpy(std::move(y), {8});
      },
      "metric"_a, "params"_a, "pos"_a, "dir"_a, "sheet"_a = 1);
  m.def(
      "origin_problems",
      [](const std::string& metric, const std::vector<double>& params, F64In origins, I32In sheets) -> nb::object {
        auto st = wv::make_spacetime(metric, params);
        const size_t n = origins.ndim() == 2 ? origins.shape(0) : 0;
        check_rows(origins, n, "origins");
        for (size_t i = 0; i < n; ++i) {
          const std::string why = st->origin_problem(origins.data() + 3 * i, sheets.data()[i]);
          if (!why.empty()) return nb::make_tuple(i, why);
        }
        return nb::none();
      },
      "metric"_a, "params"_a, "origins"_a, "sheets"_a,
      "First origin a ray cannot start from, as (row, reason), or None.");
  m.def("build_info", []() {
    nb::dict d;
    d["compiler"] = std::string(__VERSION__);
    d["flags"] = std::string(WARPVIZ_BUILD_FLAGS);
    d["hardware_threads"] = wv::resolve_threads(0);
    d["threading"] = std::string("std::thread pool, GIL released, deterministic per ray");
    return d;
  });
}
