// The camera of a render: its viewing frame as measured by the observer holding the camera (the local static
// observer, or a moving one: spacetime/observers.h) (forward, right and
// up in that observer's local frame), the start frame all camera rays share, and the direction of a
// pixel's camera sample (jittered, offset by the pixel filter) (warpviz/scene/camera.py reaches it through the binding camera_rays).
#pragma once

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/vec3.h"
#include "film/pixel_filter.h"
#include "integrators/chart_geometry.h"
#include "scene/light.h"
#include "scene/scene.h"
#include "spacetime/frame.h"
#include "spacetime/observers.h"

namespace wv {

template <class M>
class CameraRays {
 public:
  CameraRays(const M& m, const Camera& c) : c_(c) {
    const ChartGeometry<M> geo(m);
    double x4[4];
    if (!m.user_to_chart(&c.position.x, c.sheet, x4))
      throw std::invalid_argument("camera position lies outside the metric's chart");
    moving_ = c.observer.kind != ObserverKind::kLocal;
    if (!moving_ && m.absorbed(x4)) throw std::invalid_argument("camera position lies inside the horizon");
    ObserverFrame f;
    if (moving_) {
      const std::string why = observer_frame_of(m, x4, c.observer, f);
      if (!why.empty()) throw std::invalid_argument("camera observer: " + why);
    } else if (!observer_frame(m, x4, f)) {
      throw std::invalid_argument("camera position has no static or ZAMO observer");
    }
    const LinearMap L = geo.local_map(x4, f);
    to_local_ = L;
    forward_ = normalize(L(c.look_at - c.position));
    V3 up = L(c.up);
    right_ = normalize(cross(forward_, up));
    if (!(length(right_) > 0.5)) throw std::invalid_argument("camera up is parallel to the viewing direction");
    up_ = cross(right_, forward_);
    tan_half_ = std::tan(0.5 * c.fov * M_PI / 180.0);
    // every camera ray starts at the camera in its observer's frame
    start_.pos = c.position;
    start_.sheet = c.sheet;
    start_.ok = true;
    for (int i = 0; i < 4; ++i) start_.x4[i] = x4[i];
    start_.f = f;
  }

  // Direction to trace the camera ray that the camera sees along local direction d, and the energy of its
  // light there relative to the camera's. Curved space starts the ray in the camera observer's own frame
  // (start()), so both are unchanged; flat space traces straight lines in the rest frame of the static
  // observer, so a moving camera's direction is aberrated to it: the light arriving along -d has 4-momentum
  // u - d_j e_j (unit energy for the camera), whose time component is its energy for the static observer.
  V3 start_direction(V3 d, double& energy) const {
    energy = 1.0;
    if constexpr (M::kFlat) {
      if (moving_) {
        double p[4];
        const ObserverFrame& f = start_.f;
        for (int mu = 0; mu < 4; ++mu) p[mu] = f.u[mu] - d.x * f.e[0][mu] - d.y * f.e[1][mu] - d.z * f.e[2][mu];
        energy = p[0];
        return normalize(V3{-p[1], -p[2], -p[3]});
      }
    }
    return d;
  }

  // Chart point and observer frame at the camera, where every camera ray starts.
  const StartFrames::Entry& start() const { return start_; }

  // Local-frame direction of the camera sample at (jx, jy) in [0, 1)^2 of pixel (px, py) (uniform jitter or
  // the pixel's stratified point): with the box filter of the pixel itself, at px + jx, py + jy; with any
  // other filter, offset from the pixel's centre by the filter's importance sample of (jx, jy)
  // (film/pixel_filter.h), whose weight the sample's radiance is multiplied by.
  V3 direction_sample(int px, int py, double jx, double jy, const PixelFilter& filter, double& weight) const {
    weight = 1.0;
    if (filter.kind() == kBoxFilter && filter.radius() == 0.5) return direction_at(px + jx, py + jy);
    double wx, wy;
    const double ox = filter.sample(jx, wx), oy = filter.sample(jy, wy);
    weight = wx * wy;
    return direction_at(px + 0.5 + ox, py + 0.5 + oy);
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

  // Continuous pixel coordinates (x, y) of the camera ray along local direction d (direction_at's inverse);
  // false for a direction behind the image plane.
  bool pixel_of(V3 d, double& x, double& y) const {
    const Camera& cam = c_;
    const double f = dot(d, forward_);
    if (!(f > 0.0)) return false;
    const double aspect = double(cam.width) / cam.height;
    x = 0.5 * cam.width * (dot(d, right_) / (f * tan_half_ * aspect) + 1.0);
    y = 0.5 * cam.height * (1.0 - dot(d, up_) / (f * tan_half_));
    return std::isfinite(x) && std::isfinite(y);
  }

  // User-frame displacement at the camera -> its observer's local frame; whether that observer is the
  // local static one (not a moving camera's).
  const LinearMap& to_local() const { return to_local_; }
  bool static_observer() const { return !moving_; }

  // The viewing frame in the local observer's frame at the camera.
  V3 forward() const { return forward_; }
  V3 right() const { return right_; }
  V3 up() const { return up_; }

 private:
  const Camera& c_;
  StartFrames::Entry start_;
  bool moving_ = false;  // held by an observer other than the local static one (start_.f is its frame)
  V3 forward_, right_, up_;
  double tan_half_ = 1.0;
  LinearMap to_local_;
};

}  // namespace wv
