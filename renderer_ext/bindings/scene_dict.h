// Builds a Scene from the native scene dictionary (docs/native-scene.md).
#pragma once

#include <nanobind/nanobind.h>

#include "scene/scene.h"

namespace wv {

// Throws std::invalid_argument naming the offending key (e.g. "shapes[2].radius must be > 0").
void scene_from_dict(const nanobind::dict& d, Scene& scene);

}  // namespace wv
