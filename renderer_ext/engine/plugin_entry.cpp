// Compiled into every metric plugin (engine/plugin.h), never into the core: the plugin's own registry
// functions collect what its metric file registers at load time, and two exported C functions let the
// core check the layout key and take the entries.
#include <utility>

#include "engine/plugin.h"

namespace wv {

namespace {
PluginExports& collected() {
  static PluginExports exports;
  return exports;
}
}  // namespace

void register_metric(MetricEntry entry) { collected().metrics.push_back(std::move(entry)); }
void register_stepper(StepperEntry entry) { collected().steppers.push_back(std::move(entry)); }

}  // namespace wv

extern "C" __attribute__((visibility("default"))) const char* warpviz_plugin_abi() {
  static const std::string key = wv::plugin_abi_key();
  return key.c_str();
}

extern "C" __attribute__((visibility("default"))) void warpviz_plugin_take(wv::PluginExports* out) {
  *out = std::move(wv::collected());
  wv::collected() = {};
}
