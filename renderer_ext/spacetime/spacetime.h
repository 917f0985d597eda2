// Run-time face of a metric: the Spacetime interface the bindings (and later the renderer) use, and
// SpacetimeImpl<M>, which instantiates the integration loop for metric M and every stepper.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "integrators/path_tracer.h"
#include "spacetime/geodesic.h"
#include "spacetime/ray_batch.h"
#include "spacetime/steppers/dop853.h"
#include "spacetime/steppers/dopri5.h"
#include "spacetime/steppers/rk4.h"

namespace wv {

struct TraceRequest {
  std::size_t n = 0;
  const double* origins = nullptr;     // (n, 3) user frame
  const double* directions = nullptr;  // (n, 3) unit vectors in the local observer frame
  const int32_t* sheets = nullptr;     // (n,) +1 / -1, or nullptr for all +1
  TraceOptions options;
  StepperKind stepper = StepperKind::kDopri5;
  int threads = 0;
  bool batch = true;           // rays step in SIMD lanes (ray_batch.h); false: one ray at a time
  std::function<bool()> poll;  // called periodically from the calling thread; false cancels
};

struct TraceResult {
  std::vector<int8_t> status;
  std::vector<double> final_positions, final_directions;  // (n, 3)
  std::vector<int32_t> final_sheets;
  std::vector<int64_t> n_steps;
  std::vector<double> drift;  // (K, n): invariant k of ray i at [k * n + i]
  // Recording (record = true): concatenated points, offsets (n + 1), per-point columns (C, P).
  std::vector<double> points;
  std::vector<int64_t> offsets;
  std::vector<double> columns;
  int num_columns = 0;
  bool completed = true;
};

class Spacetime {
 public:
  virtual ~Spacetime() = default;
  virtual std::string name() const = 0;
  virtual std::vector<std::string> invariant_names() const = 0;
  virtual double horizon_radius() const = 0;
  virtual void inverse_metric(const double x[4], double gi[4][4]) const = 0;
  virtual void rhs(const double y[8], double dy[8]) const = 0;
  virtual void rhs_autodiff(const double y[8], double dy[8]) const = 0;
  virtual void invariants(const double y[8], double* out) const = 0;
  // Empty if a ray may start at pos on sheet, otherwise why not.
  virtual std::string origin_problem(const double pos[3], int sheet) const = 0;
  // Initial state for a ray starting at pos (user frame) along unit direction dir of the local observer.
  virtual bool initial_state(const double pos[3], const double dir[3], int sheet, double y[8]) const = 0;
  // The local observer's frame at chart point x (closed form where the metric has one, or the generic
  // construction); false where there is none.
  virtual bool observer_frame(const double x[4], bool generic, ObserverFrame& f) const = 0;
  virtual TraceResult trace(const TraceRequest& req) const = 0;
  // Path-traces `scene` (whose metric must be this one) with the given stepper.
  virtual RenderResult render(const Scene& scene, const RenderOptions& options, StepperKind stepper) const = 0;
};

template <class M>
class SpacetimeImpl final : public Spacetime {
 public:
  explicit SpacetimeImpl(M metric) : m_(metric) {}

  std::string name() const override { return M::kName; }
  std::vector<std::string> invariant_names() const override {
    return std::vector<std::string>(M::kInvariantNames, M::kInvariantNames + M::kNumInvariants);
  }
  double horizon_radius() const override { return m_.horizon_radius(); }
  void inverse_metric(const double x[4], double gi[4][4]) const override { m_.inverse_metric(x, gi); }
  void rhs(const double y[8], double dy[8]) const override { m_.rhs(y, dy); }
  void rhs_autodiff(const double y[8], double dy[8]) const override { wv::rhs_autodiff(m_, y, dy); }
  void invariants(const double y[8], double* out) const override { m_.invariants(y, out); }

  std::string origin_problem(const double pos[3], int sheet) const override {
    double x[4];
    if (!m_.user_to_chart(pos, sheet, x)) return m_.outside_chart_message(pos);
    if (m_.absorbed(x)) return "lies inside the horizon (r = " + std::to_string(m_.radius(x)) +
                               " <= r+ = " + std::to_string(m_.horizon_radius()) + ")";
    ObserverFrame f;
    if (!wv::observer_frame(m_, x, f)) return "has no static or zero-angular-momentum observer there";
    return {};
  }

  bool initial_state(const double pos[3], const double dir[3], int sheet, double y[8]) const override {
    return photon_state(m_, pos, dir, sheet, y);
  }

  bool observer_frame(const double x[4], bool generic, ObserverFrame& f) const override {
    return generic ? observer_frame_generic(m_, x, f) : wv::observer_frame(m_, x, f);
  }

  TraceResult trace(const TraceRequest& req) const override {
    switch (req.stepper) {
      case StepperKind::kRk4: return run<Rk4<M>>(req);
      case StepperKind::kDop853: return run<Dop853<M>>(req);
      default: return run<Dopri5<M>>(req);
    }
  }

  RenderResult render(const Scene& scene, const RenderOptions& options, StepperKind stepper) const override {
    switch (stepper) {
      case StepperKind::kRk4: return render_scene<M, Rk4<M>>(m_, scene, options);
      case StepperKind::kDop853: return render_scene<M, Dop853<M>>(m_, scene, options);
      default: return render_scene<M, Dopri5<M>>(m_, scene, options);
    }
  }

 private:
  template <class S>
  TraceResult run(const TraceRequest& req) const {
    constexpr int K = M::kNumInvariants;
    const std::size_t n = req.n;
    TraceResult out;
    out.status.assign(n, kNaN);
    out.final_positions.assign(3 * n, 0.0);
    out.final_directions.assign(3 * n, 0.0);
    out.final_sheets.assign(n, 1);
    out.n_steps.assign(n, 0);
    out.drift.assign(K * n, 0.0);
    std::vector<Track> tracks(req.options.record ? n : 0);
    auto setup = [&](std::size_t i, double y[8], int& sheet) {
      sheet = req.sheets ? req.sheets[i] : 1;
      if (!initial_state(req.origins + 3 * i, req.directions + 3 * i, sheet, y)) {
        throw std::invalid_argument("ray " + std::to_string(i) + " " +
                                    origin_problem(req.origins + 3 * i, sheet));
      }
    };
    auto track_of = [&](std::size_t i) { return req.options.record ? &tracks[i] : nullptr; };
    auto done = [&](std::size_t i, const RayResult& res) {
      out.status[i] = int8_t(res.status);
      for (int c = 0; c < 3; ++c) {
        out.final_positions[3 * i + c] = res.pos[c];
        out.final_directions[3 * i + c] = res.dir[c];
      }
      out.final_sheets[i] = res.sheet;
      out.n_steps[i] = res.n_steps;
      for (int k = 0; k < K; ++k) out.drift[k * n + i] = res.drift[k];
    };
    bool lanes = false;
    if constexpr (kLanesFor<M>) {
      if (req.batch) {
        // Blocks of rays, each traced through the SIMD lanes on one thread.
        constexpr std::size_t kBlock = 256;
        const std::size_t blocks = (n + kBlock - 1) / kBlock;
        auto block = [&](std::size_t b) {
          trace_lanes<M, BatchOf<S>>(m_, req.options, b * kBlock, std::min(n, (b + 1) * kBlock), setup, track_of,
                                     done);
        };
        out.completed = parallel_for(blocks, req.threads, 1, block, req.poll);
        lanes = true;
      }
    }
    if (!lanes) {
      auto body = [&](std::size_t i) {
        double y[8];
        int sheet = 1;
        setup(i, y, sheet);
        RayResult res;
        integrate_ray<M, S>(m_, y, sheet, req.options, res, track_of(i));
        done(i, res);
      };
      out.completed = parallel_for(n, req.threads, 16, body, req.poll);
    }
    if (req.options.record) {
      const int C = track_columns<M>();
      out.num_columns = C;
      out.offsets.assign(n + 1, 0);
      for (std::size_t i = 0; i < n; ++i) out.offsets[i + 1] = out.offsets[i] + int64_t(tracks[i].xyz.size() / 3);
      const std::size_t P = std::size_t(out.offsets[n]);
      out.points.reserve(3 * P);
      out.columns.assign(std::size_t(C) * P, 0.0);
      for (std::size_t i = 0; i < n; ++i) {
        out.points.insert(out.points.end(), tracks[i].xyz.begin(), tracks[i].xyz.end());
        const std::size_t base = std::size_t(out.offsets[i]), np = tracks[i].xyz.size() / 3;
        for (std::size_t j = 0; j < np; ++j)
          for (int c = 0; c < C; ++c) out.columns[std::size_t(c) * P + base + j] = tracks[i].cols[j * C + c];
        Track().xyz.swap(tracks[i].xyz);
        Track().cols.swap(tracks[i].cols);
      }
    }
    return out;
  }

  M m_;
};

}  // namespace wv
