// Tracing a bundle of rays through metric M with stepper S: each ray's start from a point and a direction
// of the local observer, the rays in blocks over threads (in SIMD lanes where the metric's right-hand
// side runs in them), and the results and recorded tracks packed into flat arrays.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "spacetime/frame.h"
#include "spacetime/geodesic.h"
#include "spacetime/ray_batch.h"
#include "spacetime/steppers/common.h"
#include "spacetime/track.h"

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
  std::vector<double> drift, drift_scaled;  // (K, n): RayResult's, invariant k of ray i at [k * n + i]
  std::vector<double> initial_states, final_states;  // (n, 8): chart state (x^mu, p_mu) at start and end
  // Recording (record = true): concatenated points, offsets (n + 1), per-point columns (C, P).
  std::vector<double> points;
  std::vector<int64_t> offsets;
  std::vector<double> columns;
  int num_columns = 0;
  bool completed = true;
};

// Empty if a ray of metric m may start at user-frame point pos on sheet, otherwise why not.
template <class M>
std::string origin_problem(const M& m, const double pos[3], int sheet, bool moving = false) {
  double x[4];
  if (!m.user_to_chart(pos, sheet, x)) return m.outside_chart_message(pos);
  if (!moving && m.absorbed(x)) return "lies inside the horizon (r = " + std::to_string(m.radius(x)) +
                             " <= r+ = " + std::to_string(m.horizon_radius()) + ")";
  if (m.escape_limit() > 0.0 && !(m.radius(x) < m.escape_limit()))
    return "lies beyond the metric's escape radius (r = " + std::to_string(m.radius(x)) +
           " >= " + std::to_string(m.escape_limit()) + ", inside which its chart holds)";
  ObserverFrame f;
  if (!moving && !wv::observer_frame(m, x, f)) return "has no static or zero-angular-momentum observer there";
  return {};
}

// Traces every ray of req with stepper S (which must be req.stepper's), on req.threads threads.
template <class M, class S>
TraceResult trace_bundle(const M& m, const TraceRequest& req) {
  constexpr int K = M::kNumInvariants;
  const std::size_t n = req.n;
  TraceResult out;
  out.status.assign(n, kNaN);
  out.final_positions.assign(3 * n, 0.0);
  out.final_directions.assign(3 * n, 0.0);
  out.final_sheets.assign(n, 1);
  out.n_steps.assign(n, 0);
  out.drift.assign(K * n, 0.0);
  out.drift_scaled.assign(K * n, 0.0);
  out.initial_states.assign(8 * n, 0.0);
  out.final_states.assign(8 * n, 0.0);
  std::vector<Track> tracks(req.options.record ? n : 0);
  auto setup = [&](std::size_t i, double y[8], int& sheet) {
    sheet = req.sheets ? req.sheets[i] : 1;
    if (!photon_state(m, req.origins + 3 * i, req.directions + 3 * i, sheet, y)) {
      throw std::invalid_argument("ray " + std::to_string(i) + " " +
                                  origin_problem(m, req.origins + 3 * i, sheet));
    }
    for (int c = 0; c < 8; ++c) out.initial_states[8 * i + c] = y[c];
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
    for (int k = 0; k < K; ++k) {
      out.drift[k * n + i] = res.drift[k];
      out.drift_scaled[k * n + i] = res.drift_scaled[k];
    }
    for (int c = 0; c < 8; ++c) out.final_states[8 * i + c] = res.y[c];
  };
  bool lanes = false;
  if constexpr (kLanesFor<M>) {
    if (req.batch) {
      // Blocks of rays, each traced through the SIMD lanes on one thread.
      constexpr std::size_t kBlock = 256;
      const std::size_t blocks = (n + kBlock - 1) / kBlock;
      auto block = [&](std::size_t b) {
        trace_lanes<M, BatchOf<S>>(m, req.options, b * kBlock, std::min(n, (b + 1) * kBlock), setup, track_of,
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
      integrate_ray<M, S>(m, y, sheet, req.options, res, track_of(i));
      done(i, res);
    };
    out.completed = parallel_for(n, req.threads, 16, body, req.poll);
  }
  if (req.options.record) {
    const int C = track_columns<M>();
    out.num_columns = C;
    PackedTracks packed = pack_tracks(n, C, [&](std::size_t i) -> Track& { return tracks[i]; });
    out.points = std::move(packed.points);
    out.offsets = std::move(packed.offsets);
    out.columns = std::move(packed.columns);
  }
  return out;
}

}  // namespace wv
