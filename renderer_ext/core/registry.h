// Registry of metrics by name: each metric file registers a factory with WARPVIZ_REGISTER_METRIC,
// so adding a metric is one file plus one line in CMakeLists.txt (Mitsuba-style plugins).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "spacetime/spacetime.h"

namespace wv {

struct MetricEntry {
  std::string name;
  std::vector<std::string> params;      // constructor parameters, in order
  std::vector<std::string> invariants;  // conserved quantities, [0] = "H"
  std::function<std::unique_ptr<Spacetime>(const std::vector<double>&)> make;
};

std::vector<MetricEntry>& metric_registry();
// Throws std::invalid_argument naming the known metrics if `name` is not registered.
const MetricEntry& find_metric(const std::string& name);
// Builds a spacetime; throws std::invalid_argument on a wrong parameter count or invalid values.
std::unique_ptr<Spacetime> make_spacetime(const std::string& name, const std::vector<double>& params);

struct MetricRegistrar {
  MetricRegistrar(MetricEntry entry) { metric_registry().push_back(std::move(entry)); }
};

}  // namespace wv

// Registers metric struct M (constructible from std::vector<double> params) under M::kName.
#define WARPVIZ_REGISTER_METRIC(M, ...)                                                                  \
  static ::wv::MetricRegistrar warpviz_registrar_##M(::wv::MetricEntry{                                 \
      M::kName, std::vector<std::string> __VA_ARGS__,                                                    \
      std::vector<std::string>(M::kInvariantNames, M::kInvariantNames + M::kNumInvariants),             \
      [](const std::vector<double>& p) -> std::unique_ptr<::wv::Spacetime> {                             \
        return std::make_unique<::wv::SpacetimeImpl<M>>(M(p));                                           \
      }})
