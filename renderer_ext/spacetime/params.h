// Parameter checks shared by the metric constructors: clear errors naming the metric and parameter.
#pragma once

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace wv {

inline double checked_param(const std::string& metric, const std::string& name, double value, double lo,
                            bool lo_open, double hi, bool hi_open) {
  const bool ok = std::isfinite(value) && (lo_open ? value > lo : value >= lo) && (hi_open ? value < hi : value <= hi);
  if (!ok) {
    std::ostringstream s;
    s << metric << ": " << name << " must be finite and in " << (lo_open ? "(" : "[") << lo << ", " << hi
      << (hi_open ? ")" : "]") << ", got " << value;
    throw std::invalid_argument(s.str());
  }
  return value;
}

}  // namespace wv
