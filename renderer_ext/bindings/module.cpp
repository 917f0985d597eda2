// Thin Python bindings: arrays in, arrays out. Validation with user-facing messages and every default live
// in Python (warpviz/tracing/trace.py, warpviz/render/render.py); this layer converts and checks only what would otherwise
// be undefined behaviour (array shapes). Test hooks are in testing.cpp, bound as _core._testing.
#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "bindings/arrays.h"
#include "bindings/scene_dict.h"
#include "core/parallel.h"
#include "core/simd.h"
#include "engine/plugin.h"
#include "engine/registry.h"
#include "integrators/guide_tree.h"

namespace nb = nanobind;
using namespace nb::literals;

namespace wv::bindings {
void bind_testing(nb::module_& m);
}

namespace {

using namespace wv::bindings;

// Names of the per-point columns of recorded paths (geodesic.h, Track).
nb::list column_names(const std::string& metric) {
  nb::list names;
  for (const auto& c : wv::track_column_names(wv::find_metric(metric).invariants)) names.append(c);
  return names;
}

wv::StepperKind stepper_kind(const std::string& s) {
  if (s == "rk4") return wv::StepperKind::kRk4;
  if (s == "dopri5") return wv::StepperKind::kDopri5;
  if (s == "dop853") return wv::StepperKind::kDop853;
  throw std::invalid_argument("unknown stepper '" + s + "' (known: rk4, dopri5, dop853)");
}

nb::dict trace(const std::string& metric, const std::vector<double>& params, F64In origins, F64In directions,
               I32In sheets, double tol, const std::string& stepper, long max_steps, double escape_radius,
               double max_drift, double rk4_step, bool record, int threads, bool batch, int monitor_every) {
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
    r = wv::trace_rays(metric, params, req);
  }
  if (interrupted) throw nb::python_error();
  const auto& names = wv::find_metric(metric).invariants;
  const size_t K = names.size();
  nb::dict out;
  nb::dict drift, drift_scaled;
  for (size_t k = 0; k < K; ++k) {
    std::vector<double> col(r.drift.begin() + k * n, r.drift.begin() + (k + 1) * n);
    drift[names[k].c_str()] = to_numpy(std::move(col), {n});
    std::vector<double> col_s(r.drift_scaled.begin() + k * n, r.drift_scaled.begin() + (k + 1) * n);
    drift_scaled[names[k].c_str()] = to_numpy(std::move(col_s), {n});
  }
  out["status"] = to_numpy(std::move(r.status), {n});
  out["final_positions"] = to_numpy(std::move(r.final_positions), {n, 3});
  out["final_directions"] = to_numpy(std::move(r.final_directions), {n, 3});
  out["final_sheets"] = to_numpy(std::move(r.final_sheets), {n});
  out["n_steps"] = to_numpy(std::move(r.n_steps), {n});
  out["invariant_drift"] = drift;
  out["invariant_drift_scaled"] = drift_scaled;
  out["initial_states"] = to_numpy(std::move(r.initial_states), {n, 8});
  out["final_states"] = to_numpy(std::move(r.final_states), {n, 8});
  if (record) {
    const size_t P = r.points.size() / 3, C = size_t(r.num_columns);
    out["points"] = to_numpy(std::move(r.points), {P, 3});
    out["offsets"] = to_numpy(std::move(r.offsets), {n + 1});
    out["columns"] = to_numpy(std::move(r.columns), {C, P});
    out["column_names"] = column_names(metric);
  }
  return out;
}



// ------------------------------------------------------------------------------------------------- film
// The film crosses into Python between ranges of samples (warpviz/render/passes.py) as a dict of numpy
// arrays: its sums and counts, moved out, and copied back in for the next range.

template <class T>
nb::object film_array(std::vector<T>&& v, size_t H, size_t W, size_t C) {
  if (v.empty()) return nb::none();  // an AOV the film does not keep
  return C == 1 ? to_numpy(std::move(v), {H, W}) : to_numpy(std::move(v), {H, W, C});
}

nb::dict film_to_dict(wv::Film&& f) {
  const size_t H = size_t(f.height), W = size_t(f.width);
  nb::dict d;
  d["x0"] = f.x0;
  d["y0"] = f.y0;
  wv::Film::for_each_array(f, [&](const char* name, auto& v, size_t c, auto) {
    d[name] = film_array(std::move(v), H, W, c);
  });
  return d;
}

// Array `key` of a film dict: C-contiguous (H, W[, C]) of type T; null for None where optional.
template <class T>
const T* film_data(const nb::dict& d, const char* key, size_t H, size_t W, size_t C, bool optional) {
  if (!d.contains(key)) throw std::invalid_argument(std::string("film: '") + key + "' is missing");
  nb::object o = d[key];
  if (o.is_none()) {
    if (optional) return nullptr;
    throw std::invalid_argument(std::string("film: '") + key + "' must be an array");
  }
  nb::ndarray<const T, nb::c_contig, nb::device::cpu> a;
  const bool ok = nb::try_cast(o, a) && a.ndim() == (C == 1 ? 2u : 3u) && a.shape(0) == H && a.shape(1) == W &&
                  (C == 1 || a.shape(2) == C);
  if (!ok) throw std::invalid_argument(std::string("film: '") + key + "' must be a C-contiguous array of shape (" +
                                       std::to_string(H) + ", " + std::to_string(W) +
                                       (C == 1 ? "" : ", " + std::to_string(C)) + ") and the film's type");
  return a.data();
}

// One array of a film dict, copied into v (an AOV the film does not keep: None, v empty).
template <class T>
void film_vector(const nb::dict& d, const char* key, size_t H, size_t W, size_t C, std::vector<T>& v) {
  const T* p = film_data<T>(d, key, H, W, C, true);
  if (p) v.assign(p, p + H * W * C);
  else v.clear();
}

// A film dict's window size (H, W), from its sample counts.
std::pair<size_t, size_t> film_shape(const nb::dict& d) {
  nb::ndarray<const int32_t, nb::c_contig, nb::device::cpu> samples;
  if (!d.contains("samples") || !nb::try_cast(d["samples"], samples) || samples.ndim() != 2)
    throw std::invalid_argument("film: 'samples' must be an int32 array of shape (H, W)");
  return {samples.shape(0), samples.shape(1)};
}

wv::Film film_from_dict(const nb::dict& d) {
  wv::Film f;
  if (!d.contains("x0") || !d.contains("y0"))
    throw std::invalid_argument("film must be a dict made by the renderer");
  f.x0 = nb::cast<int>(d["x0"]);
  f.y0 = nb::cast<int>(d["y0"]);
  const auto [H, W] = film_shape(d);
  f.height = int(H);
  f.width = int(W);
  wv::Film::for_each_array(f, [&](const char* name, auto& v, size_t c, auto) { film_vector(d, name, H, W, c, v); });
  return f;
}

// A film dict's sums and counts, read in place (checked like film_from_dict; the dict keeps them alive).
struct SumsIn {
  wv::FilmSums sums;
  size_t H = 0, W = 0;
};

SumsIn sums_from_dict(const nb::dict& d) {
  SumsIn in;
  std::tie(in.H, in.W) = film_shape(d);
  const size_t H = in.H, W = in.W;
  in.sums.n = H * W;
  in.sums.rgb_sum = film_data<double>(d, "rgb_sum", H, W, 3, false);
  in.sums.rgb_sq_sum = film_data<double>(d, "rgb_sq_sum", H, W, 3, false);
  in.sums.samples = film_data<int32_t>(d, "samples", H, W, 1, false);
  in.sums.errors = film_data<int32_t>(d, "errors", H, W, 1, false);
  in.sums.steps_sum = film_data<double>(d, "steps_sum", H, W, 1, true);
  in.sums.albedo_sum = film_data<double>(d, "albedo_sum", H, W, 3, true);
  in.sums.albedo_normal_sum = film_data<double>(d, "albedo_normal_sum", H, W, 3, true);
  in.sums.emission_sum = film_data<double>(d, "emission_sum", H, W, 3, true);
  return in;
}

// The film resolved to the image's float32 arrays (film/film.h: resolve), read in place: rgb and variance
// (H, W, 3), errors and samples (H, W), n_steps (H, W), albedo, albedo_normal and emission (H, W, 3) where the film
// keeps them (else None), and the totals of samples and of samples with errors.
nb::dict resolve_film(nb::dict film) {
  const SumsIn in = sums_from_dict(film);
  wv::ResolvedFilm r;
  {
    nb::gil_scoped_release release;
    r = wv::resolve(in.sums);
  }
  const size_t H = in.H, W = in.W;
  auto opt = [&](std::vector<float>&& v, size_t C) -> nb::object {
    if (v.empty()) return nb::none();
    return C == 1 ? to_numpy(std::move(v), {H, W}) : to_numpy(std::move(v), {H, W, C});
  };
  nb::dict out;
  out["rgb"] = to_numpy(std::move(r.rgb), {H, W, 3});
  out["variance"] = to_numpy(std::move(r.variance), {H, W, 3});
  out["errors"] = to_numpy(std::move(r.errors), {H, W});
  out["samples"] = to_numpy(std::move(r.samples), {H, W});
  out["n_steps"] = opt(std::move(r.n_steps), 1);
  out["albedo"] = opt(std::move(r.albedo), 3);
  out["albedo_normal"] = opt(std::move(r.albedo_normal), 3);
  out["emission"] = opt(std::move(r.emission), 3);
  out["samples_total"] = r.samples_total;
  out["errors_total"] = r.errors_total;
  return out;
}

// A render option; Python resolves every default and checks every value against its table (warpviz/options.py),
// so each is present; a missing one is an error naming it (tests/test_render_options.py).
template <class T>
T option(const nb::dict& o, const char* key) {
  T v;
  if (!o.contains(key) || !nb::try_cast<T>(o[key], v))
    throw std::invalid_argument(std::string("render option '") + key + "' is missing or has the wrong type");
  return v;
}

// Path guiding's tree (integrators/guide_tree.h) as the dict of arrays a render returns as "guide" (space_index,
// space_split, sky_sum, sky_child, leaf_root, roots, leaf_lights: GuideTree::Arrays), and back:
// the later ranges of the render (passes, tiles, a resumed range) are handed it instead of training again.
nb::dict guide_to_dict(const wv::GuideTree& g) {
  wv::GuideTree::Arrays a = g.arrays();
  const size_t ns = a.space_split.size(), nq = a.sky_sum.size() / 4, nl = a.leaf_root.size(), nr = a.roots.size();
  nb::dict d;
  d["space_index"] = to_numpy(std::move(a.space_index), {ns, 4});
  d["space_split"] = to_numpy(std::move(a.space_split), {ns});
  d["sky_sum"] = to_numpy(std::move(a.sky_sum), {nq, 4});
  d["sky_child"] = to_numpy(std::move(a.sky_child), {nq, 4});
  d["leaf_root"] = to_numpy(std::move(a.leaf_root), {nl});
  const size_t nlights = nl > 0 ? a.leaf_lights.size() / nl : 0;
  d["leaf_lights"] = to_numpy(std::move(a.leaf_lights), {nl, nlights});
  d["roots"] = to_numpy(std::move(a.roots), {nr});
  return d;
}

std::shared_ptr<const wv::GuideTree> guide_from(nb::handle h) {
  auto bad = [](const std::string& why) { return std::invalid_argument("render option 'guide': " + why); };
  nb::dict d;
  if (!nb::try_cast(h, d)) throw bad("must be the dict a render returned as 'guide'");
  auto i32 = [&](const char* key) {
    I32In v;
    if (!d.contains(key) || !nb::try_cast(d[key], v)) throw bad(std::string("'") + key + "' must be an int32 array");
    return std::vector<int32_t>(v.data(), v.data() + v.size());
  };
  auto f64 = [&](const char* key) {
    F64In v;
    if (!d.contains(key) || !nb::try_cast(d[key], v)) throw bad(std::string("'") + key + "' must be a float64 array");
    return std::vector<double>(v.data(), v.data() + v.size());
  };
  wv::GuideTree::Arrays a;
  a.space_index = i32("space_index");
  a.space_split = f64("space_split");
  a.sky_sum = f64("sky_sum");
  a.sky_child = i32("sky_child");
  a.leaf_root = i32("leaf_root");
  a.leaf_lights = f64("leaf_lights");
  a.roots = i32("roots");
  auto g = std::make_shared<wv::GuideTree>();
  const std::string why = g->load(a);
  if (!why.empty()) throw bad(why);
  return g;
}

// The photons' marks (integrators/photon_aim.h) as the dict a render returns as "photon_aim" (offsets, cells), and
// back: the later ranges of the render are handed them instead of learning them again.
nb::dict photon_aim_to_dict(const wv::PhotonAim& a) {
  std::vector<int64_t> offsets;
  std::vector<uint16_t> cells;
  a.to_arrays(offsets, cells);
  nb::dict d;
  const size_t no = offsets.size(), nc = cells.size();
  d["offsets"] = to_numpy(std::move(offsets), {no});
  d["cells"] = to_numpy(std::move(cells), {nc});
  return d;
}

std::shared_ptr<const wv::PhotonAim> photon_aim_from(nb::handle h) {
  auto bad = [](const std::string& why) { return std::invalid_argument("render option 'photon_aim_marks': " + why); };
  nb::dict d;
  nb::ndarray<const int64_t, nb::c_contig, nb::device::cpu> offsets;
  nb::ndarray<const uint16_t, nb::c_contig, nb::device::cpu> cells;
  if (!nb::try_cast(h, d)) throw bad("must be the dict a render returned as 'photon_aim'");
  if (!d.contains("offsets") || !nb::try_cast(d["offsets"], offsets) || offsets.ndim() != 1)
    throw bad("'offsets' must be a 1-d int64 array");
  if (!d.contains("cells") || !nb::try_cast(d["cells"], cells) || cells.ndim() != 1)
    throw bad("'cells' must be a 1-d uint16 array");
  auto a = std::make_shared<wv::PhotonAim>();
  std::string why;
  if (!a->from_arrays(offsets.data(), offsets.size(), cells.data(), cells.size(), why)) throw bad(why);
  return a;
}

nb::dict render(nb::dict scene, nb::dict options) {
  std::string metric;
  std::vector<double> params;
  wv::metric_from_dict(scene, metric, params);
  auto st = wv::make_spacetime(metric, params);
  wv::Scene sc;
  wv::scene_from_dict(scene, sc);
  {
    const bool moving = sc.camera.observer.kind != wv::ObserverKind::kLocal;
    const std::string why = st->origin_problem(&sc.camera.position.x, sc.camera.sheet, moving);
    if (!why.empty()) throw std::invalid_argument("camera.position " + why);
  }
  wv::RenderOptions o;
  o.spp = option<int>(options, "spp");
  o.sample_begin = option<int>(options, "sample_begin");
  o.seed = uint64_t(option<long long>(options, "seed"));
  o.max_depth = option<int>(options, "max_depth");
  o.rr_depth = option<int>(options, "rr_depth");
  o.light_sampling = option<bool>(options, "light_sampling");
  o.trace.tol = option<double>(options, "tol");
  o.trace.max_steps = option<long>(options, "max_steps");
  o.trace.escape_radius = option<double>(options, "escape_radius");
  o.trace.max_drift = option<double>(options, "max_drift");
  o.chord_tol = option<double>(options, "chord_tolerance");
  {
    const std::string sm = option<std::string>(options, "segment_method");
    if (sm != "closed_form" && sm != "integrate")
      throw std::invalid_argument("segment_method must be 'closed_form' or 'integrate', got '" + sm + "'");
    o.segment_method = sm == "closed_form" ? wv::kClosedFormSegments : wv::kIntegratedSegments;
  }
  o.aim_lights = option<bool>(options, "aim_lights");
  o.light_margin = option<bool>(options, "light_margin");
  o.pilot_tol = option<double>(options, "pilot_tol");
  {
    const std::string lc = option<std::string>(options, "light_connection");
    if (lc != "lens" && lc != "images" && lc != "aimed")
      throw std::invalid_argument("light_connection must be 'lens', 'images' or 'aimed', got '" + lc + "'");
    o.light_connection = lc == "lens" ? wv::kLensConnection : lc == "images" ? wv::kImageConnection : wv::kAimedConnection;
  }
  o.lens_images = option<int>(options, "lens_images");
  o.camera_light_samples = option<bool>(options, "camera_light_samples");
  o.lens_focus = option<bool>(options, "lens_focus");
  o.stratified_paths = option<bool>(options, "stratified_paths");
  o.light_roulette = option<double>(options, "light_roulette");
  {
    const std::string ps = option<std::string>(options, "pixel_sampler");
    if (ps != "sobol" && ps != "independent")
      throw std::invalid_argument("pixel_sampler must be 'sobol' or 'independent', got '" + ps + "'");
    o.pixel_sampler = ps == "sobol" ? wv::kSobolPixels : wv::kIndependentPixels;
  }
  {
    const std::string f = option<std::string>(options, "filter");
    if (f != "box" && f != "gaussian" && f != "mitchell")
      throw std::invalid_argument("filter must be 'box', 'gaussian' or 'mitchell', got '" + f + "'");
    o.filter = f == "box" ? wv::kBoxFilter : f == "gaussian" ? wv::kGaussianFilter : wv::kMitchellFilter;
    o.filter_radius = option<double>(options, "filter_radius");
  }
  o.edge_samples = option<int>(options, "edge_samples");
  o.detail_samples = option<int>(options, "detail_samples");
  if (options.contains("pixel_classes") && !options["pixel_classes"].is_none()) {  // None: probe for them
    nb::ndarray<const int64_t, nb::c_contig, nb::device::cpu> el;
    if (!nb::try_cast(options["pixel_classes"], el) || el.ndim() != 1)
      throw std::invalid_argument("render option 'pixel_classes' must be an int64 array of shape (K,)");
    o.classes_given = true;
    o.classes.assign(el.data(), el.data() + el.size());
  }
  o.guide_training = option<int>(options, "guide_training");
  o.photons = wv::pass_photons(option<int64_t>(options, "photons"), option<double>(options, "photons_per_pixel"),
                               sc.camera.width, sc.camera.height);
  o.photon_radius = option<double>(options, "photon_radius");
  o.retro_photons = option<bool>(options, "retro_photons");
  o.photon_aim = option<bool>(options, "photon_aim");
  if (options.contains("photon_aim_marks") && !options["photon_aim_marks"].is_none())
    o.photon_aim_marks = photon_aim_from(options["photon_aim_marks"]);
  if (options.contains("guide") && !options["guide"].is_none()) {
    o.guide = guide_from(options["guide"]);
    if (o.guide->lights() != 0 && o.guide->lights() != sc.light_count())
      throw std::invalid_argument("render option 'guide' chooses among " + std::to_string(o.guide->lights()) +
                                  " lights, the scene has " + std::to_string(sc.lights.size()));
  }
  o.batch = option<bool>(options, "batch");
  o.threads = option<int>(options, "threads");
  if (options.contains("crop") && !options["crop"].is_none()) {  // None: the whole image
    const auto crop = option<std::vector<int>>(options, "crop");  // Python checked it lies in the image
    if (crop.size() != 4) throw std::invalid_argument("render option 'crop' must be (x0, y0, width, height)");
    for (int k = 0; k < 4; ++k) o.crop[k] = crop[k];
  }
  {
    const auto names = option<std::vector<std::string>>(options, "aovs");
    auto keep = [&](const char* name) { return std::find(names.begin(), names.end(), name) != names.end(); };
    o.aovs = {keep("n_steps"), keep("max_drift"), keep("redshift"), keep("status"), keep("depth"), keep("normal"),
              keep("albedo"), keep("albedo_normal"), keep("emission")};
  }
  const auto stepper = stepper_kind(option<std::string>(options, "stepper"));
  if (options.contains("record_pixels") && !options["record_pixels"].is_none()) {
    nb::ndarray<const int32_t, nb::c_contig, nb::device::cpu> rp;
    if (!nb::try_cast(options["record_pixels"], rp) || rp.ndim() != 2 || rp.shape(1) != 2)
      throw std::invalid_argument("record_pixels must be an int32 array of shape (K, 2)");
    o.record_pixels.assign(rp.data(), rp.data() + rp.size());
    o.record_samples = option<int>(options, "record_samples");
  }
  wv::Film film_in;
  if (options.contains("film") && !options["film"].is_none()) {  // the earlier ranges' sums, continued
    film_in = film_from_dict(nb::cast<nb::dict>(options["film"]));
    o.film_in = &film_in;
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
    r = wv::render_scene(metric, params, sc, o, stepper);
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (callback_error) std::rethrow_exception(callback_error);

  nb::dict out, stats;
  out["noise"] = wv::noise(wv::sums_of(r.film));
  out["film"] = film_to_dict(std::move(r.film));
  const size_t nclasses = r.pixel_classes.size();
  out["pixel_classes"] = to_numpy(std::move(r.pixel_classes), {nclasses});
  out["completed"] = r.completed && !interrupted;
  if (r.guide && !r.guide->empty()) out["guide"] = guide_to_dict(*r.guide);
  if (r.photon_aim && r.photon_aim->active()) out["photon_aim"] = photon_aim_to_dict(*r.photon_aim);
  nb::dict counts;
  for (int k = 0; k < wv::kNumStatuses; ++k) counts[wv::kStatusNames[k]] = r.stats.counts[k];
  stats["segments_by_status"] = counts;
  stats["segments"] = r.stats.segments;
  stats["edge_pixels"] = r.edge_pixels;
  stats["bright_edge_pixels"] = r.bright_edge_pixels;
  stats["detail_pixels"] = r.detail_pixels;
  stats["guide_segments"] = r.guide_segments;
  stats["photon_segments"] = r.photon_segments;
  stats["photon_passes"] = r.photon_passes;
  stats["photons_stored"] = r.photons_stored;
  stats["steps"] = r.stats.steps;
  stats["light_hits"] = r.stats.light_hits;
  stats["unsampled_light_hits"] = r.stats.unsampled_light_hits;
  stats["seconds"] = seconds;
  stats["threads"] = wv::resolve_threads(o.threads);
  out["stats"] = stats;
  if (!o.record_pixels.empty()) {
    const size_t N = r.recorded.size();
    wv::PackedTracks packed =
        wv::pack_tracks(N, r.num_columns, [&](size_t i) -> wv::Track& { return r.recorded[i].track; });
    const size_t P = packed.points.size() / 3, C = size_t(r.num_columns);
    std::vector<int32_t> px(N), py(N), sample(N), bounce(N), sheet(N);
    std::vector<int8_t> kind(N), status(N);
    for (size_t i = 0; i < N; ++i) {
      const auto& seg = r.recorded[i];
      px[i] = seg.px; py[i] = seg.py; sample[i] = seg.sample; bounce[i] = seg.bounce;
      kind[i] = seg.kind; status[i] = seg.status; sheet[i] = seg.sheet;
    }
    nb::dict rays;
    rays["points"] = to_numpy(std::move(packed.points), {P, 3});
    rays["offsets"] = to_numpy(std::move(packed.offsets), {N + 1});
    rays["columns"] = to_numpy(std::move(packed.columns), {C, P});
    rays["column_names"] = column_names(metric);
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


nb::list metrics() {
  nb::list out;
  for (const auto& e : wv::registered_metrics()) {
    nb::dict d;
    d["name"] = e.name;
    d["class_name"] = e.class_name;
    d["summary"] = e.summary;
    nb::list names, specs;
    for (const auto& p : e.params) {
      names.append(p.name);
      nb::dict spec;
      spec["name"] = p.name;
      spec["lo"] = p.lo;
      spec["lo_open"] = p.lo_open;
      spec["hi"] = p.hi;
      spec["hi_open"] = p.hi_open;
      spec["default"] = p.value;
      spec["example"] = p.example;
      spec["doc"] = p.doc;
      specs.append(spec);
    }
    d["params"] = names;
    d["param_specs"] = specs;
    d["param_relation"] = e.param_relation;
    d["invariants"] = e.invariants;
    d["sheets"] = e.sheets;
    d["flat"] = e.flat;
    d["lane_rhs"] = e.lane_rhs;
    d["static_spherical"] = e.static_spherical;
    out.append(d);
  }
  return out;
}

// Landmark radii of a metric with parameters (spacetime/landmarks.h); 0 where it has none.
nb::dict landmarks(const std::string& metric, const std::vector<double>& params) {
  const wv::Landmarks l = wv::make_spacetime(metric, params)->landmarks();
  nb::dict d;
  d["horizon"] = l.horizon;
  d["inner_horizon"] = l.inner_horizon;
  d["capture"] = l.capture;
  d["photon_sphere"] = l.photon_sphere;
  d["photon_prograde"] = l.photon_prograde;
  d["photon_retrograde"] = l.photon_retrograde;
  d["photon_polar"] = l.photon_polar;
  d["ergosphere"] = l.ergosphere;
  d["throat"] = l.throat;
  d["mass"] = l.mass;
  d["spin"] = l.spin;
  d["escape"] = l.escape;
  return d;
}

// A static spherical metric's lens-map functions (spacetime/lens_map.h): the coefficients of A(u) and h(u)
// in u = 1 / R, the innermost 1 / R its rays approach and whether that sphere is a throat; None for others.
nb::object spherical_lens(const std::string& metric, const std::vector<double>& params) {
  wv::SphericalLens s;
  if (!wv::make_spacetime(metric, params)->spherical_lens(s)) return nb::none();
  nb::dict d;
  d["a"] = std::vector<double>(s.a, s.a + wv::SphericalLens::kMaxCoef);
  d["h"] = std::vector<double>(s.h, s.h + wv::SphericalLens::kMaxCoef);
  d["u_inner"] = s.u_inner;
  d["throat"] = s.throat;
  return d;
}

}  // namespace

NB_MODULE(_core, m) {
  m.doc() = "warpviz native core: null geodesics of the spacetimes registered in renderer_ext/metrics/";
  m.def(
      "sample_multiples",
      [](int edge_samples, int detail_samples) {
        const wv::SampleMultiples k = wv::sample_multiples(edge_samples, detail_samples);
        return nb::make_tuple(k.plain, k.edge, k.detail, k.bright_edge);
      },
      "edge_samples"_a, "detail_samples"_a,
      "The multiples of spp a render's pixels get (integrators/render_types.h): plain, edge, detail, bright edge.");
  m.def(
      "photon_pass_bytes",
      [](int64_t photons, double photons_per_pixel, int width, int height) {
        const int64_t n = wv::pass_photons(photons, photons_per_pixel, width, height);
        return nb::make_tuple(n, n * int64_t(wv::kPhotonPassBytes));
      },
      "photons"_a, "photons_per_pixel"_a, "width"_a, "height"_a,
      "A photon pass's photons for a width x height image, and the most memory in bytes the pass holds at once "
      "(every photon stored): integrators/render_types.h.");
  m.def("metrics", &metrics, "Registered metrics and their facts (engine/registry.h).");
  m.def("load_metric_plugin", &wv::load_metric_plugin, "path"_a,
        "Loads a metric plugin once and enters its metrics and steppers into the registry (engine/plugin.h); "
        "returns the names of the metrics it added.");
  m.def(
      "has_stepper",
      [](const std::string& metric, const std::string& stepper, bool render) {
        return wv::has_stepper(metric, stepper_kind(stepper), render);
      },
      "metric"_a, "stepper"_a, "render"_a,
        "Whether the registry has the metric's tracer (render=False) or renderer for the stepper.");
  m.def("plugin_abi_key", &wv::plugin_abi_key, "The layout key a metric plugin must match (engine/plugin.h).");
  m.def("status_names", []() {
    std::vector<std::string> names(wv::kStatusNames, wv::kStatusNames + wv::kNumStatuses);
    return names;
  }, "How a ray can end, by status code (spacetime/geodesic.h).");
  m.def("landmarks", &landmarks, "metric"_a, "params"_a, "Landmark radii of a metric (spacetime/landmarks.h).");
  m.def("spherical_lens", &spherical_lens, "metric"_a, "params"_a,
        "A static spherical metric's A(u) and h(u) coefficients, u_inner and throat flag "
        "(spacetime/lens_map.h); None for the others.");
  m.def(
      "params_problem",
      [](const std::string& metric, const std::vector<double>& params) {
        return wv::params_problem(wv::find_metric(metric), params);
      },
      "metric"_a, "params"_a, "Empty if the parameters are valid for the metric, else why not.");
  m.def("render", &render, "scene"_a, "options"_a,
        "Path-trace samples [sample_begin, sample_begin + spp) of a native scene dict (docs/native-scene.md) "
        "into a film (continuing options['film'], if given); see warpviz.render.");
  m.def("resolve_film", &resolve_film, "film"_a, "A film's per-pixel means and AOVs as float32 arrays.");
  m.def(
      "film_noise", [](nb::dict film) { return wv::noise(sums_from_dict(film).sums); }, "film"_a,
      "A film's relative noise estimate (film/film.h: noise; warpviz.render.passes.noise_estimate).");
  m.def(
      "film_noise_parts",
      [](nb::dict film) {
        const wv::NoiseParts p = wv::noise_parts(sums_from_dict(film).sums);
        return nb::make_tuple(p.var, p.level, p.lit);
      },
      "film"_a, "The sums a film's noise estimate is made of, (var, level, lit), which add over tiles (film/film.h).");
  m.def(
      "noise_from_parts",
      [](double var, double level, size_t lit) { return wv::noise(wv::NoiseParts{var, level, lit}); }, "var"_a,
      "level"_a, "lit"_a, "The noise estimate from film_noise_parts' sums, added over tiles (film/film.h: noise).");
  m.def("trace", &trace, "metric"_a, "params"_a, "origins"_a, "directions"_a, "sheets"_a, "tol"_a, "stepper"_a,
        "max_steps"_a, "escape_radius"_a, "max_drift"_a, "rk4_step"_a, "record"_a, "threads"_a, "batch"_a, "monitor_every"_a,
        "Trace rays; see warpviz.trace for the documented interface.");
  m.def(
      "origin_problems",
      [](const std::string& metric, const std::vector<double>& params, F64In origins, I32In sheets,
         bool moving) -> nb::object {
        auto st = wv::make_spacetime(metric, params);
        const size_t n = origins.ndim() == 2 ? origins.shape(0) : 0;
        check_rows(origins, n, "origins");
        for (size_t i = 0; i < n; ++i) {
          const std::string why = st->origin_problem(origins.data() + 3 * i, sheets.data()[i], moving);
          if (!why.empty()) return nb::make_tuple(i, why);
        }
        return nb::none();
      },
      "metric"_a, "params"_a, "origins"_a, "sheets"_a, "moving"_a = false,
      "First origin a ray cannot start from, as (row, reason), or None; moving: for a camera held by a moving "
      "observer, which may be inside a horizon (spacetime/observers.h).");
  m.def(
      "camera_rays",
      [](const std::string& metric, const std::vector<double>& params, nb::dict camera, F64In pixels) {
        if (pixels.ndim() != 2 || pixels.shape(1) != 2) throw std::invalid_argument("pixels must have shape (n, 2)");
        wv::Camera cam;
        wv::camera_from_dict(camera, cam);
        const size_t n = pixels.shape(0);
        std::vector<double> frame(9), directions(3 * n);
        wv::make_spacetime(metric, params)->camera_rays(cam, pixels.data(), n, frame.data(), directions.data());
        return nb::make_tuple(to_numpy(std::move(frame), {3, 3}), to_numpy(std::move(directions), {n, 3}));
      },
      "metric"_a, "params"_a, "camera"_a, "pixels"_a,
      "The render camera's frame (rows forward, right, up) and its rays' directions through continuous pixel "
      "coordinates (n, 2), in the local observer's frame at the camera (integrators/camera.h).");
  m.def(
      "observer",
      [](const std::string& metric, const std::vector<double>& params, nb::dict camera) {
        wv::Camera cam;
        wv::camera_from_dict(camera, cam);
        double x[4];
        wv::ObserverFrame f;
        const std::string why =
            wv::make_spacetime(metric, params)->observer_at(&cam.position.x, cam.sheet, cam.observer, x, f);
        if (!why.empty()) throw std::invalid_argument(why);
        std::vector<double> xv(x, x + 4), u(f.u, f.u + 4), e(&f.e[0][0], &f.e[0][0] + 12), g(&f.g[0][0], &f.g[0][0] + 16);
        return nb::make_tuple(to_numpy(std::move(xv), {4}), to_numpy(std::move(u), {4}), to_numpy(std::move(e), {3, 4}),
                              to_numpy(std::move(g), {4, 4}));
      },
      "metric"_a, "params"_a, "camera"_a,
      "The camera observer at its position (spacetime/observers.h): chart point x (4,), 4-velocity u (4,), "
      "spatial triad e (3, 4) and covariant metric g (4, 4); ValueError saying why no such observer can be there.");
  m.def(
      "worldline",
      [](const std::string& metric, const std::vector<double>& params, nb::dict camera, F64In taus,
         double stop_radius, double tol) {
        wv::Camera cam;
        wv::camera_from_dict(camera, cam);
        auto st = wv::make_spacetime(metric, params);
        double x[4];
        wv::ObserverFrame f;
        const std::string why = st->observer_at(&cam.position.x, cam.sheet, cam.observer, x, f);
        if (!why.empty()) throw std::invalid_argument(why);
        const int n = int(taus.ndim() == 1 ? taus.shape(0) : 0);
        std::vector<wv::WorldlinePoint> pts(n);
        int k;
        {
          nb::gil_scoped_release unlocked;
          k = st->worldline(x, f.u, cam.sheet, taus.data(), n, stop_radius, tol, pts.data());
        }
        std::vector<double> xs(4 * k), us(4 * k), pos(3 * k);
        std::vector<int32_t> sheets(k);
        for (int i = 0; i < k; ++i) {
          for (int a = 0; a < 4; ++a) {
            xs[4 * i + a] = pts[i].x[a];
            us[4 * i + a] = pts[i].u[a];
          }
          for (int a = 0; a < 3; ++a) pos[3 * i + a] = pts[i].pos[a];
          sheets[i] = pts[i].sheet;
        }
        const size_t K = size_t(k);
        return nb::make_tuple(to_numpy(std::move(pos), {K, 3}), to_numpy(std::move(sheets), {K}),
                              to_numpy(std::move(xs), {K, 4}), to_numpy(std::move(us), {K, 4}));
      },
      "metric"_a, "params"_a, "camera"_a, "taus"_a, "stop_radius"_a, "tol"_a,
      "The worldline of the camera's observer, a timelike geodesic (spacetime/worldline.h), at proper times taus "
      "(n,): user positions (k, 3), sheets (k,), chart points (k, 4) and 4-velocities (k, 4), k <= n where it "
      "stopped (below stop_radius, or the chart's end).");
  nb::module_ testing = m.def_submodule("_testing", "Test hooks (not public API)");
  wv::bindings::bind_testing(testing);
  m.def("build_info", []() {
    nb::dict d;
    d["compiler"] = std::string(__VERSION__);
    d["flags"] = std::string(WARPVIZ_BUILD_FLAGS);
    d["hardware_threads"] = wv::resolve_threads(0);
    d["threading"] = std::string("std::thread pool, GIL released, deterministic per ray");
    d["simd"] = std::to_string(wv::kLanes) + "-ray batches, " + wv::lane_kernel_isa() + " kernel";
    d["lane_target"] = std::string(wv::lane_kernel_target());
    return d;
  });
}
