// The camera of a render: its viewing frame as measured by the observer at the camera (forward, right and
// up in that observer's local frame), the start frame all camera rays share, and the jittered direction of
// a pixel's camera ray (warpviz/scene/camera.py reaches it through the binding camera_rays).
#pragma once

#include <cmath>
#include <stdexcept>

#include "core/rng.h"
#include "core/sobol.h"
#include "core/vec3.h"
#include "integrators/chart_geometry.h"
#include "scene/light.h"
#include "scene/scene.h"
#include "spacetime/frame.h"

namespace wv {

template <class M>
class CameraRays {
 public:
  CameraRays(const M& m, const Camera& c) : c_(c) {
    const ChartGeometry<M> geo(m);
    double x4[4];
    if (!m.user_to_chart(&c.position.x, c.sheet, x4))
      throw std::invalid_argument("camera position lies outside the metric's chart");
    if (m.absorbed(x4)) throw std::invalid_argument("camera position lies inside the horizon");
    ObserverFrame f;
    if (!observer_frame(m, x4, f)) throw std::invalid_argument("camera position has no static or ZAMO observer");
    const LinearMap L = geo.local_map(x4, f);
    forward_ = normalize(L(c.look_at - c.position));
    V3 up = L(c.up);
    right_ = normalize(cross(forward_, up));
    if (!(length(right_) > 0.5)) throw std::invalid_argument("camera up is parallel to the viewing direction");
    up_ = cross(right_, forward_);
    tan_half_ = std::tan(0.5 * c.fov * M_PI / 180.0);
    start_ = geo.start_frame(c.position, c.sheet);
  }

  // Chart point and observer frame at the camera, where every camera ray starts.
  const StartFrames::Entry& start() const { return start_; }

  // Local-frame direction of a camera ray through pixel (px, py), jittered by the next two numbers of rng.
  V3 direction(int px, int py, Rng& rng) const {
    const double x = px + rng.uniform();
    const double y = py + rng.uniform();
    return direction_at(x, y);
  }

  // The same at the sample-th point of the pixel's stratified sequence (core/sobol.h); draws nothing from rng.
  V3 direction_stratified(int px, int py, uint64_t seed, uint64_t pixel, uint64_t sample) const {
    double jx, jy;
    pixel_sample(seed, pixel, sample, jx, jy);
    return direction_at(px + jx, py + jy);
  }

  // Local-frame direction of the camera ray through continuous pixel coordinates (x, y): x to the right
  // and y down from the image's top-left corner, pixel (px, py) covering [px, px + 1) x [py, py + 1).
  V3 direction_at(double x, double y) const {
    const Camera& cam = c_;
    const double aspect = double(cam.width) / cam.height;
    const double sx = (2.0 * x / cam.width - 1.0) * tan_half_ * aspect;
    const double sy = (1.0 - 2.0 * y / cam.height) * tan_half_;
    return normalize(forward_ + right_ * sx + up_ * sy);
  }

  // The viewing frame in the local observer's frame at the camera.
  V3 forward() const { return forward_; }
  V3 right() const { return right_; }
  V3 up() const { return up_; }

 private:
  const Camera& c_;
  StartFrames::Entry start_;
  V3 forward_, right_, up_;
  double tan_half_ = 1.0;
};

}  // namespace wv
