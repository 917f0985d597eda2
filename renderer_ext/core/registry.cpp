#include "core/registry.h"

#include <stdexcept>

namespace wv {

std::vector<MetricEntry>& metric_registry() {
  static std::vector<MetricEntry> entries;
  return entries;
}

const MetricEntry& find_metric(const std::string& name) {
  for (const auto& e : metric_registry())
    if (e.name == name) return e;
  std::string known;
  for (const auto& e : metric_registry()) known += (known.empty() ? "" : ", ") + e.name;
  throw std::invalid_argument("unknown metric '" + name + "' (known: " + known + ")");
}

std::unique_ptr<Spacetime> make_spacetime(const std::string& name, const std::vector<double>& params) {
  const MetricEntry& e = find_metric(name);
  if (params.size() != e.params.size())
    throw std::invalid_argument(name + " takes " + std::to_string(e.params.size()) + " parameters, got " +
                                std::to_string(params.size()));
  return e.make(params);
}

}  // namespace wv
