// The registry of metrics: the single source of every metric fact (name, Python class name, parameters
// with ranges and defaults, the relation between them, conserved quantities, sheets, flatness, whether a
// hand-written right-hand side runs in SIMD lanes) and the way to trace and render with any of them.
//
// Each metric file registers itself with one line, WARPVIZ_REGISTER_METRIC (engine/register.h), so a new
// metric is one file plus one CMake line (warpviz_add_metric), Mitsuba-style. A metric file is compiled
// in two halves (CMakeLists.txt, engine/register.h), each registering its part of the tracers and
// renderers, one also the metric's facts; lookups merge them. A metric compiled at run time (a line
// element) enters the same tables when its plugin is loaded (engine/plugin.h).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/spacetime.h"
#include "integrators/render_types.h"
#include "scene/scene.h"
#include "spacetime/bundle.h"
#include "spacetime/params.h"
#include "spacetime/steppers/common.h"

namespace wv {

struct MetricEntry {
  std::string name;        // registry name, e.g. "kerr"
  std::string class_name;  // Python class, e.g. "Kerr"
  std::string summary;     // one line
  std::vector<ParamSpec> params;
  std::string param_relation;  // constraint between parameters, in words ("" if none)
  std::vector<std::string> invariants;  // conserved quantities, [0] = "H"
  int sheets = 1;
  bool flat = false;
  bool lane_rhs = false;  // a hand-written right-hand side that runs in SIMD lanes (else ~6x slower, by AD)
  bool static_spherical = false;  // has an exact lens map (spacetime/lens_map.h) for the light connection
  std::string (*relation_problem)(const double*) = nullptr;
  std::function<std::unique_ptr<Spacetime>(const std::vector<double>&)> make;
};

// A metric's tracer or renderer (the other null) for one stepper, from (already validated) parameters.
struct StepperEntry {
  std::string metric;
  StepperKind stepper;
  TraceResult (*trace)(const std::vector<double>& params, const TraceRequest& req);
  RenderResult (*render)(const std::vector<double>& params, const Scene& scene, const RenderOptions& options);
};

// A copy of the registered metrics' facts, in registration order (built-in files, then loaded plugins).
std::vector<MetricEntry> registered_metrics();
// Whether a tracer (render = false) or renderer for the metric and stepper is registered.
bool has_stepper(const std::string& metric, StepperKind stepper, bool render);
// Throws std::invalid_argument naming the known metrics if `name` is not registered.
const MetricEntry& find_metric(const std::string& name);
// Empty if params (in the entry's order) are valid for the metric, otherwise why not.
std::string params_problem(const MetricEntry& entry, const std::vector<double>& params);
// Builds a spacetime; throws std::invalid_argument on a wrong parameter count or invalid values.
std::unique_ptr<Spacetime> make_spacetime(const std::string& name, const std::vector<double>& params);
// Traces req (with req.stepper) / path-traces scene through the metric; parameters are validated first.
TraceResult trace_rays(const std::string& name, const std::vector<double>& params, const TraceRequest& req);
RenderResult render_scene(const std::string& name, const std::vector<double>& params, const Scene& scene,
                          const RenderOptions& options, StepperKind stepper);

// Used by WARPVIZ_REGISTER_METRIC at static initialisation (and by engine/plugins.cpp for a loaded plugin;
// a plugin's own copies, engine/plugin_entry.cpp, collect its entries for the core instead).
void register_metric(MetricEntry entry);
void register_stepper(StepperEntry entry);

}  // namespace wv
