#include "engine/registry.h"

#include <deque>
#include <mutex>
#include <stdexcept>

namespace wv {

namespace {

// Deques: a plugin loaded while a render runs (engine/plugins.cpp) appends entries without moving the
// ones a running render holds by reference. The lock orders appends against lookups.
std::deque<MetricEntry>& metric_table() {
  static std::deque<MetricEntry> entries;
  return entries;
}

std::deque<StepperEntry>& stepper_table() {
  static std::deque<StepperEntry> entries;
  return entries;
}

std::mutex& table_lock() {
  static std::mutex m;
  return m;
}

const char* stepper_name(StepperKind s) {
  switch (s) {
    case StepperKind::kRk4: return "rk4";
    case StepperKind::kDop853: return "dop853";
    default: return "dopri5";
  }
}

const StepperEntry& find_stepper(const std::string& name, const std::vector<double>& params, StepperKind s,
                                 bool render) {
  const MetricEntry& e = find_metric(name);
  const std::string why = params_problem(e, params);
  if (!why.empty()) throw std::invalid_argument(why);
  const std::lock_guard<std::mutex> hold(table_lock());
  for (const auto& st : stepper_table())
    if (st.metric == name && st.stepper == s && (render ? st.render != nullptr : st.trace != nullptr)) return st;
  throw std::invalid_argument("metric '" + name + "' was built without the " + stepper_name(s) + " stepper");
}

}  // namespace

void register_metric(MetricEntry entry) {
  const std::lock_guard<std::mutex> hold(table_lock());
  metric_table().push_back(std::move(entry));
}
void register_stepper(StepperEntry entry) {
  const std::lock_guard<std::mutex> hold(table_lock());
  stepper_table().push_back(std::move(entry));
}

std::vector<MetricEntry> registered_metrics() {
  const std::lock_guard<std::mutex> hold(table_lock());
  return {metric_table().begin(), metric_table().end()};
}

bool has_stepper(const std::string& metric, StepperKind stepper, bool render) {
  const std::lock_guard<std::mutex> hold(table_lock());
  for (const auto& st : stepper_table())
    if (st.metric == metric && st.stepper == stepper && (render ? st.render != nullptr : st.trace != nullptr))
      return true;
  return false;
}

const MetricEntry& find_metric(const std::string& name) {
  const std::lock_guard<std::mutex> hold(table_lock());
  for (const auto& e : metric_table())
    if (e.name == name) return e;
  std::string known;
  for (const auto& e : metric_table()) known += (known.empty() ? "" : ", ") + e.name;
  throw std::invalid_argument("unknown metric '" + name + "' (known: " + known + ")");
}

std::string params_problem(const MetricEntry& e, const std::vector<double>& params) {
  if (params.size() != e.params.size())
    return e.name + " takes " + std::to_string(e.params.size()) + " parameters, got " + std::to_string(params.size());
  for (std::size_t i = 0; i < params.size(); ++i) {
    std::string why = param_problem(e.name, e.params[i], params[i]);
    if (!why.empty()) return why;
  }
  if (e.relation_problem) {
    std::string why = e.relation_problem(params.data());
    if (!why.empty()) return e.name + ": " + why;
  }
  return {};
}

std::unique_ptr<Spacetime> make_spacetime(const std::string& name, const std::vector<double>& params) {
  const MetricEntry& e = find_metric(name);
  const std::string why = params_problem(e, params);
  if (!why.empty()) throw std::invalid_argument(why);
  return e.make(params);
}

TraceResult trace_rays(const std::string& name, const std::vector<double>& params, const TraceRequest& req) {
  return find_stepper(name, params, req.stepper, false).trace(params, req);
}

RenderResult render_scene(const std::string& name, const std::vector<double>& params, const Scene& scene,
                          const RenderOptions& options, StepperKind stepper) {
  return find_stepper(name, params, stepper, true).render(params, scene, options);
}

}  // namespace wv
