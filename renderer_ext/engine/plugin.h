// Metric plugins: a metric file compiled outside the core into a shared library and loaded at run time
// (a line element's generated file: warpviz/spacetime/line_element/plugin.py). The plugin is built from the
// same headers with the same optimisation flags, so its metric runs the same tracer and renderer code as a
// built-in one; only the registry's entries cross the library boundary.
//
// A plugin is its metric file (ending in WARPVIZ_REGISTER_METRIC, with WARPVIZ_STEPPERS choosing its part,
// engine/register.h) compiled together with engine/plugin_entry.cpp, which collects what the file
// registers and exports two C functions: the layout key below and the hand-over of the entries. The core
// (engine/plugins.cpp) checks the key before it touches an entry, so a plugin built against other headers
// is refused with a message instead of crashing.
#pragma once

#include <deque>
#include <functional>
#include <string>
#include <vector>

#include "engine/registry.h"

namespace wv {

// What a plugin registered when it was loaded.
struct PluginExports {
  std::vector<MetricEntry> metrics;
  std::vector<StepperEntry> steppers;
};

// The sizes of every type that crosses the boundary, and the standard library's string ABI: a plugin
// whose key differs from the core's was built against other headers (or another warpviz).
inline std::string plugin_abi_key() {
  const std::size_t sizes[] = {sizeof(MetricEntry), sizeof(StepperEntry), sizeof(Scene),        sizeof(RenderOptions),
                               sizeof(RenderResult), sizeof(TraceRequest), sizeof(TraceResult), sizeof(ParamSpec),
                               sizeof(Landmarks),   sizeof(std::string),  sizeof(std::function<void()>),
                               sizeof(std::vector<double>)};
  std::string key = "warpviz-plugin-1";
#if defined(_GLIBCXX_USE_CXX11_ABI)
  key += "-cxx11abi" + std::to_string(_GLIBCXX_USE_CXX11_ABI);
#endif
  for (std::size_t s : sizes) key += "-" + std::to_string(s);
  return key;
}

// The functions a plugin exports (extern "C", engine/plugin_entry.cpp).
using PluginAbiFn = const char* (*)();
using PluginTakeFn = void (*)(PluginExports* out);
constexpr const char* kPluginAbiSymbol = "warpviz_plugin_abi";
constexpr const char* kPluginTakeSymbol = "warpviz_plugin_take";

// Loads the plugin at `path` once (a second call returns the same names) and enters its metrics and
// steppers into the registry. Returns the names of the metrics whose entries it added. Throws
// std::runtime_error if the library cannot be loaded, is not a warpviz plugin, was built against other
// headers, or registers a metric name that is taken or a stepper for a metric that is not registered.
std::vector<std::string> load_metric_plugin(const std::string& path);

}  // namespace wv
