// A metric's parameters as data: name, allowed range, default and a line of documentation. The registry
// (engine/registry.h) validates every parameter against its spec before a metric is constructed, and the
// Python classes, scene validation and docs are built from the same specs.
#pragma once

#include <cmath>
#include <limits>
#include <sstream>
#include <string>

namespace wv {

constexpr double kUnbounded = std::numeric_limits<double>::infinity();

struct ParamSpec {
  const char* name;
  double lo;
  bool lo_open;  // lo itself excluded
  double hi;
  bool hi_open;
  double value;     // default
  double example;   // a strong-field value the contract tests and examples use (spin 0.9, ...)
  const char* doc;  // one line: meaning and unit
};

// Empty if `value` is allowed for `spec`, otherwise why not, naming the metric and the parameter.
inline std::string param_problem(const std::string& metric, const ParamSpec& spec, double value) {
  const bool ok = std::isfinite(value) && (spec.lo_open ? value > spec.lo : value >= spec.lo) &&
                  (spec.hi_open ? value < spec.hi : value <= spec.hi);
  if (ok) return {};
  std::ostringstream s;
  s << metric << ": " << spec.name << " must be finite and in " << (spec.lo_open ? "(" : "[") << spec.lo << ", "
    << spec.hi << (spec.hi_open ? ")" : "]") << ", got " << value;
  return s.str();
}

}  // namespace wv
