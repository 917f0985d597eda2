// Converts the native scene dictionary (docs/native-scene.md) into the core's Scene, camera and metric.
//
// Conversion only: warpviz.scene.native (Python) checks every value with user-facing messages and writes
// every key, optional ones with their defaults (the one place they live). A key that is absent or has
// the wrong type here is a programming error and throws std::invalid_argument naming it; what is checked
// besides is only what would otherwise be undefined behaviour (array shapes, indices).
#pragma once

#include <nanobind/nanobind.h>

#include <string>
#include <vector>

#include "scene/material.h"
#include "scene/scene.h"

namespace wv {

// scene["metric"]: its registry name and parameters.
void metric_from_dict(const nanobind::dict& scene, std::string& name, std::vector<double>& params);
// A camera table (scene["camera"]); `where` names it in errors.
void camera_from_dict(const nanobind::dict& camera, Camera& cam, const std::string& where = "camera");
// One material table that may refer to textures [0, num_textures) (or -1: none).
Material material_from_dict(const nanobind::dict& material, const std::string& where, int num_textures);
// The whole scene: camera, textures, materials, shapes and both skies.
void scene_from_dict(const nanobind::dict& d, Scene& scene);

}  // namespace wv
