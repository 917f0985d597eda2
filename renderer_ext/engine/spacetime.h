// The run-time face of one metric with its parameters: the geometry the bindings, the test hooks and the
// registry ask of it (inverse metric, Hamilton's equations, conserved quantities, observer frames, where a
// ray may start, landmark radii, the render camera's rays). Tracing and rendering are not here: they are
// instantiated per metric and stepper by engine/register.h and reached through the registry
// (engine/registry.h).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "integrators/camera.h"
#include "scene/scene.h"
#include "spacetime/bundle.h"
#include "spacetime/frame.h"
#include "spacetime/landmarks.h"
#include "spacetime/metric.h"
#include "spacetime/observers.h"
#include "spacetime/worldline.h"

namespace wv {

class Spacetime {
 public:
  virtual ~Spacetime() = default;
  virtual std::string name() const = 0;
  virtual std::vector<std::string> invariant_names() const = 0;
  virtual Landmarks landmarks() const = 0;
  virtual void inverse_metric(const double x[4], double gi[4][4]) const = 0;
  virtual void rhs(const double y[8], double dy[8]) const = 0;
  virtual void rhs_autodiff(const double y[8], double dy[8]) const = 0;
  virtual void invariants(const double y[8], double* out) const = 0;
  // Empty if a ray may start at pos on sheet, otherwise why not; `moving`: for an observer other than the
  // local static one (spacetime/observers.h), which may be inside a horizon.
  virtual std::string origin_problem(const double pos[3], int sheet, bool moving = false) const = 0;
  // Initial state for a ray starting at pos (user frame) along unit direction dir of the local observer.
  virtual bool initial_state(const double pos[3], const double dir[3], int sheet, double y[8]) const = 0;
  // The render camera c (integrators/camera.h): its viewing frame in the local observer's frame at its
  // position (frame: rows forward, right, up) and the directions of its rays through the n continuous pixel
  // coordinates xy (x right, y down; dirs: n rows). Throws where the camera cannot be (inside a horizon).
  virtual void camera_rays(const Camera& c, const double* xy, size_t n, double frame[9], double* dirs) const = 0;
  // The local observer's frame at chart point x (closed form where the metric has one, or the generic
  // construction); false where there is none.
  virtual bool observer_frame(const double x[4], bool generic, ObserverFrame& f) const = 0;
  // The frame of observer `s` at user-frame point pos on `sheet` (spacetime/observers.h), with the chart
  // point into x; "" or why no such observer can be there.
  virtual std::string observer_at(const double pos[3], int sheet, const ObserverSpec& s, double x[4],
                                  ObserverFrame& f) const = 0;
  // The observer's worldline from chart point x0 with 4-velocity u0 on `sheet`, at proper times taus[0..n)
  // (spacetime/worldline.h); returns how many points it reached before stop_radius or the chart's end.
  virtual int worldline(const double x0[4], const double u0[4], int sheet, const double* taus, int n,
                        double stop_radius, double tol, WorldlinePoint* out) const = 0;
  // A static spherical metric's lens-map functions (spacetime/lens_map.h); false for the others.
  virtual bool spherical_lens(SphericalLens& out) const = 0;
};

template <class M>
class SpacetimeImpl final : public Spacetime {
 public:
  explicit SpacetimeImpl(M metric) : m_(metric) {}

  std::string name() const override { return M::kName; }
  std::vector<std::string> invariant_names() const override {
    return std::vector<std::string>(M::kInvariantNames, M::kInvariantNames + M::kNumInvariants);
  }
  Landmarks landmarks() const override { return m_.landmarks(); }
  void inverse_metric(const double x[4], double gi[4][4]) const override { m_.inverse_metric(x, gi); }
  void rhs(const double y[8], double dy[8]) const override { m_.rhs(y, dy); }
  void rhs_autodiff(const double y[8], double dy[8]) const override { wv::rhs_autodiff(m_, y, dy); }
  void invariants(const double y[8], double* out) const override { m_.invariants(y, out); }
  std::string origin_problem(const double pos[3], int sheet, bool moving = false) const override {
    return wv::origin_problem(m_, pos, sheet, moving);
  }
  bool initial_state(const double pos[3], const double dir[3], int sheet, double y[8]) const override {
    return photon_state(m_, pos, dir, sheet, y);
  }
  void camera_rays(const Camera& c, const double* xy, size_t n, double frame[9], double* dirs) const override {
    const CameraRays<M> rays(m_, c);
    const V3 axes[3] = {rays.forward(), rays.right(), rays.up()};
    for (int a = 0; a < 3; ++a)
      for (int k = 0; k < 3; ++k) frame[3 * a + k] = axes[a][k];
    for (size_t i = 0; i < n; ++i) {
      const V3 d = rays.direction_at(xy[2 * i], xy[2 * i + 1]);
      for (int k = 0; k < 3; ++k) dirs[3 * i + k] = d[k];
    }
  }
  bool observer_frame(const double x[4], bool generic, ObserverFrame& f) const override {
    return generic ? observer_frame_generic(m_, x, f) : wv::observer_frame(m_, x, f);
  }
  std::string observer_at(const double pos[3], int sheet, const ObserverSpec& s, double x[4],
                          ObserverFrame& f) const override {
    if (!m_.user_to_chart(pos, sheet, x)) return "the point lies outside the metric's chart";
    return observer_frame_of(m_, x, s, f);
  }
  int worldline(const double x0[4], const double u0[4], int sheet, const double* taus, int n, double stop_radius,
                double tol, WorldlinePoint* out) const override {
    return wv::worldline(m_, x0, u0, sheet, taus, n, stop_radius, tol, out);
  }
  bool spherical_lens(SphericalLens& out) const override {
    out = m_.spherical_lens();
    return M::kStaticSpherical;
  }

 private:
  M m_;
};

}  // namespace wv
