// Thin Python bindings: arrays in, arrays out. Validation with user-facing messages lives in Python
// (warpviz/trace.py); this layer only checks what would otherwise be undefined behaviour.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "bindings/scene_dict.h"
#include "core/parallel.h"
#include "core/registry.h"
#include "core/simd.h"

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

// Names of the per-point columns of recorded paths (geodesic.h, Track).
nb::list column_names(const wv::Spacetime& st) {
  nb::list names;
  for (const char* c : {"affine_param", "coord_time", "r", "step_size", "hamiltonian_err"}) names.append(c);
  const auto inv = st.invariant_names();
  for (size_t k = 1; k < inv.size(); ++k) names.append(inv[k] + "_drift");
  names.append("redshift");
  names.append("sheet");
  return names;
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
               double max_drift, double rk4_step, bool record, int threads, bool batch, int monitor_every) {
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
  req.batch = batch;
  req.options.tol = tol;
  req.options.max_steps = max_steps;
  req.options.escape_radius = escape_radius;
  req.options.max_drift = max_drift;
  req.options.rk4_step = rk4_step;
  req.options.record = record;
  req.options.monitor_every = monitor_every;
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
    out["column_names"] = column_names(*st);
  }
  return out;
}


template <class T>
T option(const nb::dict& o, const char* key, T dflt) {
  if (!o.contains(key) || o[key].is_none()) return dflt;
  T v;
  if (!nb::try_cast<T>(o[key], v)) throw std::invalid_argument(std::string("render option '") + key + "' has the wrong type");
  return v;
}

nb::dict render(nb::dict scene, nb::dict options) {
  if (!scene.contains("metric")) throw std::invalid_argument("scene.metric is missing");
  nb::dict md = nb::cast<nb::dict>(scene["metric"]);
  const std::string metric = nb::cast<std::string>(md["name"]);
  const std::vector<double> params = md.contains("params") ? nb::cast<std::vector<double>>(md["params"]) : std::vector<double>{};
  auto st = wv::make_spacetime(metric, params);
  wv::Scene sc;
  wv::scene_from_dict(scene, sc);
  {
    const std::string why = st->origin_problem(&sc.camera.position.x, sc.camera.sheet);
    if (!why.empty()) throw std::invalid_argument("camera.position " + why);
  }
  wv::RenderOptions o;
  o.spp = option<int>(options, "spp", 16);
  o.seed = uint64_t(option<long long>(options, "seed", 0));
  o.max_depth = option<int>(options, "max_depth", 8);
  o.rr_depth = option<int>(options, "rr_depth", 3);
  o.light_sampling = option<bool>(options, "light_sampling", true);
  o.trace.tol = option<double>(options, "tol", 1e-7);
  o.trace.max_steps = option<long>(options, "max_steps", 20000);
  o.trace.escape_radius = option<double>(options, "escape_radius", 1e3);
  o.trace.max_drift = option<double>(options, "max_drift", std::max(1e-6, 1e3 * o.trace.tol));
  o.chord_tol = option<double>(options, "chord_tolerance", 1e-3);
  o.aim_lights = option<bool>(options, "aim_lights", true);
  o.light_margin = option<bool>(options, "light_margin", true);
  o.pilot_tol = option<double>(options, "pilot_tol", 1e-4);
  o.batch = option<bool>(options, "batch", true);
  o.threads = option<int>(options, "threads", 0);
  const auto stepper = stepper_kind(option<std::string>(options, "stepper", "dopri5"));
  if (o.spp < 1) throw std::invalid_argument("spp must be >= 1");
  if (o.max_depth < 1) throw std::invalid_argument("max_depth must be >= 1");
  if (!(o.trace.tol > 0 && o.trace.tol < 1)) throw std::invalid_argument("tol must be in (0, 1)");
  if (!(o.chord_tol > 0)) throw std::invalid_argument("chord_tolerance must be > 0");
  if (!(o.pilot_tol > 0 && o.pilot_tol < 1)) throw std::invalid_argument("pilot_tol must be in (0, 1)");
  if (options.contains("record_pixels") && !options["record_pixels"].is_none()) {
    nb::ndarray<const int32_t, nb::c_contig, nb::device::cpu> rp;
    if (!nb::try_cast(options["record_pixels"], rp) || rp.ndim() != 2 || rp.shape(1) != 2)
      throw std::invalid_argument("record_pixels must be an int32 array of shape (K, 2)");
    o.record_pixels.assign(rp.data(), rp.data() + rp.size());
  }
  nb::object progress = options.contains("progress") ? nb::object(options["progress"]) : nb::none();
  bool interrupted = false;
  std::exception_ptr callback_error;
  o.poll = [&](int64_t done, int64_t total) {
    nb::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) {
      PyErr_Clear();  // keep the partial image; Python reports the interruption
      interrupted = true;
      return false;
    }
    if (!progress.is_none()) {
      try {
        progress(done, total);
      } catch (nb::python_error& e) {
        if (e.matches(PyExc_KeyboardInterrupt)) interrupted = true;
        else callback_error = std::current_exception();
        return false;
      }
    }
    return true;
  };
  const auto t0 = std::chrono::steady_clock::now();
  wv::RenderResult r;
  {
    nb::gil_scoped_release release;
    r = st->render(sc, o, stepper);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (callback_error) std::rethrow_exception(callback_error);
  if (!progress.is_none() && r.completed && !interrupted) {
    const int64_t total = int64_t(r.film.width) * r.film.height * o.spp;
    progress(total, total);
  }

  const wv::Film& f = r.film;
  const size_t W = size_t(f.width), H = size_t(f.height), n = W * H;
  std::vector<float> rgb(3 * n), steps(n), errors(n), samples(n);
  for (size_t i = 0; i < n; ++i) {
    const double c = f.samples[i] > 0 ? 1.0 / f.samples[i] : 0.0;
    for (int k = 0; k < 3; ++k) rgb[3 * i + k] = float(f.rgb_sum[3 * i + k] * c);
    steps[i] = float(f.steps_sum[i] * c);
    errors[i] = float(f.errors[i] * c);
    samples[i] = float(f.samples[i]);
  }
  nb::dict out, aovs, stats;
  out["rgb"] = to_numpy(std::move(rgb), {H, W, 3});
  aovs["redshift"] = to_numpy(std::vector<float>(f.redshift), {H, W});
  aovs["n_steps"] = to_numpy(std::move(steps), {H, W});
  aovs["max_drift"] = to_numpy(std::vector<float>(f.max_drift), {H, W});
  aovs["status"] = to_numpy(std::vector<float>(f.status), {H, W});
  aovs["depth"] = to_numpy(std::vector<float>(f.depth), {H, W});
  aovs["normal"] = to_numpy(std::vector<float>(f.normal), {H, W, 3});
  aovs["errors"] = to_numpy(std::move(errors), {H, W});
  aovs["samples"] = to_numpy(std::move(samples), {H, W});
  out["aovs"] = aovs;
  out["completed"] = r.completed && !interrupted;
  const char* status_names[] = {"escaped", "hit", "horizon", "max_steps", "invariant_violation", "nan"};
  nb::dict counts;
  for (int k = 0; k < 6; ++k) counts[status_names[k]] = r.status_counts[k];
  stats["segments_by_status"] = counts;
  stats["segments"] = r.segments;
  stats["steps"] = r.total_steps;
  stats["seconds"] = seconds;
  stats["threads"] = wv::resolve_threads(o.threads);
  out["stats"] = stats;
  if (!o.record_pixels.empty()) {
    const size_t N = r.recorded.size(), C = size_t(r.num_columns);
    std::vector<int64_t> offsets(N + 1, 0);
    for (size_t i = 0; i < N; ++i) offsets[i + 1] = offsets[i] + int64_t(r.recorded[i].track.xyz.size() / 3);
    const size_t P = size_t(offsets[N]);
    std::vector<double> points;
    points.reserve(3 * P);
    std::vector<double> cols(C * P);
    std::vector<int32_t> px(N), py(N), sample(N), bounce(N), sheet(N);
    std::vector<int8_t> kind(N), status(N);
    for (size_t i = 0; i < N; ++i) {
      const auto& seg = r.recorded[i];
      points.insert(points.end(), seg.track.xyz.begin(), seg.track.xyz.end());
      const size_t np = seg.track.xyz.size() / 3, base = size_t(offsets[i]);
      for (size_t j = 0; j < np; ++j)
        for (size_t c = 0; c < C; ++c) cols[c * P + base + j] = seg.track.cols[j * C + c];
      px[i] = seg.px; py[i] = seg.py; sample[i] = seg.sample; bounce[i] = seg.bounce;
      kind[i] = seg.kind; status[i] = seg.status; sheet[i] = seg.sheet;
    }
    nb::dict rays;
    rays["points"] = to_numpy(std::move(points), {P, 3});
    rays["offsets"] = to_numpy(std::move(offsets), {N + 1});
    rays["columns"] = to_numpy(std::move(cols), {C, P});
    rays["column_names"] = column_names(*st);
    rays["pixel_x"] = to_numpy(std::move(px), {N});
    rays["pixel_y"] = to_numpy(std::move(py), {N});
    rays["sample"] = to_numpy(std::move(sample), {N});
    rays["bounce"] = to_numpy(std::move(bounce), {N});
    rays["kind"] = to_numpy(std::move(kind), {N});
    rays["status"] = to_numpy(std::move(status), {N});
    rays["sheet"] = to_numpy(std::move(sheet), {N});
    out["rays"] = rays;
  }
  return out;
}


// Test hook for the BSDFs: samples material `material` (a native material dict, constant albedo) at
// local normal n for outgoing direction wo with the given uniforms u (N, 3), and evaluates the BSDF at
// the sampled directions and at the given directions `at` (M, 3). Returns wi (N, 3), weight (N, 3),
// pdf (N,), delta (N,), valid (N,), f_eval (N, 3) (= BSDF |cos|, 0 for delta lobes), pdf_eval (N,),
// f_at (M, 3) and pdf_at (M,).
nb::dict bsdf(nb::dict material, std::vector<double> albedo, std::vector<double> n, std::vector<double> wo, F64In u,
              F64In at) {
  if (albedo.size() != 3 || n.size() != 3 || wo.size() != 3) throw std::invalid_argument("albedo, n and wo need 3 components");
  if (u.ndim() != 2 || u.shape(1) != 3) throw std::invalid_argument("u must have shape (N, 3)");
  if (at.ndim() != 2 || at.shape(1) != 3) throw std::invalid_argument("at must have shape (M, 3)");
  nb::dict scene;
  nb::list mats;
  mats.append(material);
  scene["materials"] = mats;
  wv::Scene sc;
  nb::dict cam;
  cam["position"] = std::vector<double>{0, 0, 1};
  cam["look_at"] = std::vector<double>{0, 0, 0};
  scene["camera"] = cam;
  scene["shapes"] = nb::list();
  wv::scene_from_dict(scene, sc);
  const wv::Material& m = sc.materials.at(0);
  const wv::V3 A(albedo.data()), N = wv::normalize(wv::V3(n.data())), WO = wv::normalize(wv::V3(wo.data()));
  const size_t count = u.shape(0);
  std::vector<double> wi(3 * count), weight(3 * count), pdf(count), fe(3 * count), pe(count);
  std::vector<int8_t> delta(count), valid(count);
  for (size_t i = 0; i < count; ++i) {
    const double* ui = u.data() + 3 * i;
    const wv::BsdfSample b = wv::bsdf_sample(m, A, N, WO, ui[0], ui[1], ui[2]);
    double pev = 0.0;
    const wv::V3 f = wv::bsdf_eval(m, A, N, WO, b.wi, pev);
    for (int c = 0; c < 3; ++c) {
      wi[3 * i + c] = b.wi[c];
      weight[3 * i + c] = b.weight[c];
      fe[3 * i + c] = f[c];
    }
    pdf[i] = b.pdf;
    pe[i] = pev;
    delta[i] = b.delta;
    valid[i] = b.valid;
  }
  const size_t M = at.shape(0);
  std::vector<double> f_at(3 * M), pdf_at(M);
  for (size_t i = 0; i < M; ++i) {
    const wv::V3 f = wv::bsdf_eval(m, A, N, WO, wv::normalize(wv::V3(at.data() + 3 * i)), pdf_at[i]);
    for (int c = 0; c < 3; ++c) f_at[3 * i + c] = f[c];
  }
  nb::dict out;
  out["f_at"] = to_numpy(std::move(f_at), {M, 3});
  out["pdf_at"] = to_numpy(std::move(pdf_at), {M});
  out["wi"] = to_numpy(std::move(wi), {count, 3});
  out["weight"] = to_numpy(std::move(weight), {count, 3});
  out["pdf"] = to_numpy(std::move(pdf), {count});
  out["delta"] = to_numpy(std::move(delta), {count});
  out["valid"] = to_numpy(std::move(valid), {count});
  out["f_eval"] = to_numpy(std::move(fe), {count, 3});
  out["pdf_eval"] = to_numpy(std::move(pe), {count});
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
  m.def("render", &render, "scene"_a, "options"_a,
        "Path-trace a native scene dict (docs/native-scene.md); see warpviz.render.");
  m.def("bsdf", &bsdf, "material"_a, "albedo"_a, "n"_a, "wo"_a, "u"_a, "at"_a,
        "Test hook: sample and evaluate one material's BSDF in a local frame.");
  m.def("trace", &trace, "metric"_a, "params"_a, "origins"_a, "directions"_a, "sheets"_a, "tol"_a, "stepper"_a,
        "max_steps"_a, "escape_radius"_a, "max_drift"_a, "rk4_step"_a, "record"_a, "threads"_a, "batch"_a, "monitor_every"_a,
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
      "observer_frame",
      [](const std::string& metric, const std::vector<double>& params, F64In x, bool generic) -> nb::object {
        auto st = wv::make_spacetime(metric, params);
        const auto xv = copy1(x, 4, "x");
        wv::ObserverFrame f;
        if (!st->observer_frame(xv.data(), generic, f)) return nb::none();
        return nb::make_tuple(to_numpy(std::vector<double>(&f.g[0][0], &f.g[0][0] + 16), {4, 4}),
                              to_numpy(std::vector<double>(f.u, f.u + 4), {4}),
                              to_numpy(std::vector<double>(&f.e[0][0], &f.e[0][0] + 12), {3, 4}));
      },
      "metric"_a, "params"_a, "x"_a, "generic"_a = false,
      "Test hook: (g_{mu nu}, u^mu, e_j^mu) of the local observer at chart point x, or None.");
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
    d["simd"] = std::to_string(wv::kLanes) + "-ray batches, " + wv::lane_kernel_isa() + " kernel";
    return d;
  });
}
