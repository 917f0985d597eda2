// Loading metric plugins into the registry (engine/plugin.h).
#include <dlfcn.h>

#include <map>
#include <mutex>
#include <stdexcept>

#include "engine/plugin.h"

namespace wv {

std::vector<std::string> load_metric_plugin(const std::string& path) {
  static std::mutex lock;
  static std::map<std::string, std::vector<std::string>> loaded;  // path -> the metrics it added
  const std::lock_guard<std::mutex> hold(lock);
  if (auto it = loaded.find(path); it != loaded.end()) return it->second;

  // RTLD_LOCAL: the plugin's copies of the shared code stay its own. A plugin is never unloaded: the
  // registry keeps pointers into it for the life of the process.
  void* lib = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (lib == nullptr) {
    const char* why = dlerror();
    throw std::runtime_error("cannot load metric plugin " + path + ": " + (why ? why : "unknown error"));
  }
  auto abi = reinterpret_cast<PluginAbiFn>(dlsym(lib, kPluginAbiSymbol));
  auto take = reinterpret_cast<PluginTakeFn>(dlsym(lib, kPluginTakeSymbol));
  if (abi == nullptr || take == nullptr)
    throw std::runtime_error(path + " is not a warpviz metric plugin (it exports no " + kPluginAbiSymbol + ")");
  const std::string theirs = abi(), ours = plugin_abi_key();
  if (theirs != ours)
    throw std::runtime_error(path + " was built against other warpviz headers (layout " + theirs +
                             ", this core " + ours + "): delete it and compile the metric again");
  PluginExports got;
  take(&got);

  // Check everything before entering anything, so a refused plugin leaves the registry as it was.
  std::vector<std::string> names;
  for (const auto& m : got.metrics) {
    for (const auto& e : registered_metrics())
      if (e.name == m.name) throw std::runtime_error(path + " registers metric '" + m.name + "', which is taken");
    names.push_back(m.name);
  }
  for (const auto& s : got.steppers) {
    bool known = false;
    for (const auto& n : names) known = known || n == s.metric;
    for (const auto& e : registered_metrics()) known = known || e.name == s.metric;
    if (!known)
      throw std::runtime_error(path + " registers a stepper for metric '" + s.metric +
                               "', which is not registered: load the plugin with its facts first");
    if (has_stepper(s.metric, s.stepper, s.render != nullptr))
      throw std::runtime_error(path + " registers a stepper that metric '" + s.metric + "' already has");
  }
  for (auto& m : got.metrics) register_metric(std::move(m));
  for (auto& s : got.steppers) register_stepper(std::move(s));
  loaded[path] = names;
  return names;
}

}  // namespace wv
