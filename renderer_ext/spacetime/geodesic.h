// Integrating one null geodesic: the ray state machine (stepping, conserved-quantity monitoring,
// termination status, horizon/escape crossings located on the dense output, recording) and integrate_ray.
// The asymptotic direction of escaped rays is in asymptotics.h, the recorded polyline in track.h, the
// step-size control in steppers/step_control.h.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/fastmath.h"
#include "core/root.h"
#include "spacetime/asymptotics.h"
#include "spacetime/frame.h"
#include "spacetime/metric.h"
#include "spacetime/steppers/step_control.h"
#include "spacetime/track.h"

namespace wv {

enum RayStatus : int8_t {
  kEscaped = 0,
  kHit = 1,
  kHorizon = 2,
  kMaxSteps = 3,
  kInvariantViolation = 4,
  kNaN = 5,
};
constexpr int kNumStatuses = 6;
// Their names, the one list the bindings and Python's RayStatus follow.
inline constexpr const char* kStatusNames[kNumStatuses] = {"escaped", "hit", "horizon", "max_steps",
                                                           "invariant_violation", "nan"};

struct TraceOptions {
  double tol = 1e-9;            // relative + absolute local error per step (adaptive steppers)
  long max_steps = 100000;      // budget of step attempts, accepted or rejected
  double escape_radius = 1e3;   // rays moving outward beyond this radius have escaped
  double max_drift = 1e-6;      // largest allowed term-scaled drift (RayResult::drift_scaled) of any
                                // conserved quantity at a monitored point
  double rk4_step = 1.0;        // base (far-field) step of the seed RK4 method
  bool record = false;          // keep the polyline and per-point data
  bool backward = false;        // past-directed ray (camera rays): captured at the metric's capture radius
  // Accepted steps between evaluations of the conserved quantities other than H (H costs nothing and is
  // checked every step); crossings and ends are always checked. 0: every step when recording or at
  // tol < 1e-8, else every 4th (a drift needs far more than 4 steps to grow from ~tol to max_drift).
  int monitor_every = 0;
};

// A conserved quantity whose value at the start is below this fraction of the largest size its terms
// have had along the ray so far (Q of an equatorial ray, Lz of a ray that starts near the axis and
// leaves it) is negligible: the integration error scales with those terms, so its relative drift says
// nothing and the term-scaled one is reported from that point on.
inline constexpr double kNegligibleInvariant = 1e-6;

struct RayResult {
  int status = kNaN;
  double pos[3] = {0, 0, 0};  // final position, user frame
  double dir[3] = {0, 0, 0};  // asymptotic direction (escaped) or coordinate direction of motion
  int sheet = 1;
  long n_steps = 0;
  // Drifts of the conserved quantities X_k, maxima over the monitored points and the end state (see
  // kNegligibleInvariant). drift_scaled: |X - X0| / S, S the largest size along the ray of the terms X is
  // computed from (at least the metric's invariant_scales floor); [0] is |2H| over the size of its
  // terms. The check against max_drift uses it. drift: the reported drift, at each point |X - X0| / |X0|
  // while X0 is not negligible against the terms' largest size so far, the term-scaled drift from then
  // on (and always for H, which is 0).
  double drift[kMaxInvariants] = {0, 0, 0, 0, 0, 0};
  double drift_scaled[kMaxInvariants] = {0, 0, 0, 0, 0, 0};
  double y[8] = {0, 0, 0, 0, 0, 0, 0, 0};  // final chart state (position and covariant momentum)
  int prim = -1;                           // surface hit (status kHit): the scene primitive
  double first_step = 0.0, last_step = 0.0;  // the first and the last accepted step (0 if none)
};

// Surfaces tested along each accepted step (none for plain geodesics). A surface set provides
//   static constexpr bool kActive = true;
//   static constexpr bool kDenseEnd;    // true: the state at a hit is the step's dense output there where
//                                       // the stepper's dense output is as accurate as its step
//                                       // (kAccurateDense); otherwise a full-order step to the hit
//   template <class S> bool find(const S& stepper, const double* y, const double* ynew, double h, int sheet,
//                                double& theta, int& prim);
// returning the fraction theta of the step at which the path first crosses a surface.
struct NoSurfaces {
  static constexpr bool kActive = false;
  static constexpr bool kDenseEnd = false;
};

inline bool state_finite(const double y[8]) {
  for (int i = 0; i < 8; ++i)
    if (!std::isfinite(y[i])) return false;
  return true;
}

template <class M>
bool moving_outward(const M& m, const double y[8]) {
  double f[8];
  m.rhs(y, f);
  return y[1] * f[1] + y[2] * f[2] + y[3] * f[3] > 0.0;
}

// Straight line to the escape sphere: Minkowski needs no integration at all.
template <class M>
void straight_ray(const M& m, const double y[8], int sheet, const TraceOptions& o, RayResult& res, Track* track) {
  double v[3] = {y[5], y[6], y[7]};
  const double vn = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (double& c : v) c /= vn;
  const double* x = y + 1;
  const double b = x[0] * v[0] + x[1] * v[1] + x[2] * v[2];
  const double c = x[0] * x[0] + x[1] * x[1] + x[2] * x[2] - o.escape_radius * o.escape_radius;
  // distance s >= 0 along v to |x + s v| = R (0 if already outside and moving out)
  double s = 0.0;
  if (c < 0.0 || b < 0.0) s = -b + std::sqrt(std::max(0.0, b * b - c));
  res.status = kEscaped;
  res.sheet = sheet;
  res.n_steps = 0;
  for (int i = 0; i < 3; ++i) {
    res.pos[i] = x[i] + s * v[i];
    res.dir[i] = v[i];
  }
  if (track) {
    for (int k = 0; k < 2; ++k) {
      const double* pk = k == 0 ? x : res.pos;
      track->xyz.insert(track->xyz.end(), pk, pk + 3);
      const double lam = k == 0 ? 0.0 : s;  // p^0 = 1, so affine parameter = distance = time
      const double r = std::sqrt(pk[0] * pk[0] + pk[1] * pk[1] + pk[2] * pk[2]);
      const double row[] = {lam, y[0] + lam, r, k == 0 ? 0.0 : s, 0.0};
      track->cols.insert(track->cols.end(), row, row + 5);
      for (int j = 1; j < M::kNumInvariants; ++j) track->cols.insert(track->cols.end(), {0.0, 0.0});  // reported, scaled
      track->cols.push_back(1.0);  // no shift in flat space
      track->cols.push_back(double(sheet));
    }
  }
  (void)m;
}

// One ray's integration, resumable one step attempt at a time, so the same logic drives a ray on its
// own (integrate_ray) and a ray in one lane of a SIMD batch (ray_batch.h):
//
//   GeodesicRay<M, S, Surf> ray;
//   if (ray.begin(m, y, sheet, options, res, track, surfaces)) {   // false: finished already
//     st.init(m, ray.y);
//     while (ray.next()) {                                          // false: out of step budget
//       const double e = st.attempt(m, ray.y, ray.h, options.tol, ynew);
//       if (!ray.advance(st, e, ynew)) break;                       // false: the ray has ended
//     }
//   }
//
// S is the stepper (or, in a batch, a view of one lane of the batch stepper); `advance` may call its
// dense output, re-attempt partial steps to reach a crossing, and accept() / init() it.
template <class M, class S, class Surf = NoSurfaces>
class GeodesicRay {
 public:
  static constexpr int K = M::kNumInvariants;
  double y[8] = {0, 0, 0, 0, 0, 0, 0, 0};  // state to step from
  double h = 0.0;                          // step to attempt next
  double log_err_prev = 0.0;               // step control: log error of the last accepted step (>= 1e-4)

  // Sets up the ray from state y0 (chart coordinates, covariant momentum) on `sheet`. Returns false if
  // the ray ended already (flat space, a non-finite start, or already beyond its escape target).
  // first_step > 0: the step to attempt first where the caller knows one (a segment leaving the point where the
  // last one ended, whose last accepted step it is), at most the largest allowed; else that largest step.
  bool begin(const M& m, const double y0[8], int sheet, const TraceOptions& o, RayResult& res, Track* track,
             Surf* surfaces = nullptr, double first_step = 0.0) {
    m_ = &m;
    o_ = &o;
    res_ = &res;
    track_ = track;
    surfaces_ = surfaces;
    sheet_ = sheet;
    for (int i = 0; i < 8; ++i) y[i] = y0[i];
    if constexpr (M::kFlat) {
      straight_ray(m, y, sheet, o, res, track);
      return false;
    } else {
      const HamiltonianParts hp0 = hamiltonian_parts(m, y);
      for (int k = 0; k < K; ++k) mag_[k] = 0.0;
      inv0_[0] = 0.5 * hp0.two_h;
      m.conserved(y, hp0, inv0_, mag_);
      m.invariant_scales(y, inv0_, scale_);
      // Like H below, each conserved quantity's drift is measured against the largest size of the
      // terms it is computed from along the ray (at least its scale at the start): where momenta grow
      // large (backward rays near a horizon) the cancellation in those terms limits what can be
      // conserved.
      for (int k = 1; k < K; ++k) scale_[k] = std::max(scale_[k], mag_[k]);
      relative_[0] = false;
      for (int k = 1; k < K; ++k) relative_[k] = std::fabs(inv0_[k]) >= kNegligibleInvariant * scale_[k];
      for (int k = 0; k < K; ++k) drift_[k] = reported_[k] = 0.0;
      // H is measured relative to the largest size its terms had along the ray: the rounding and
      // truncation errors committed where the coordinate momenta were large (e.g. an outgoing ray
      // starting just outside a horizon) do not grow as the momenta shrink, and no step-size
      // reduction later could remove them.
      h_scale_ = 0.0;
      drift_[0] = reported_[0] = herr_of(hp0);
      for (int k = 0; k < K; ++k) res.drift[k] = res.drift_scaled[k] = drift_[k];
      res.n_steps = 0;
      lam_ = 0.0;
      energy0_ = track ? local_energy(m, y) : 0.0;

      record(y, 0.0, 0.0);
      if (!state_finite(y)) return finish(kNaN, y);

      r_h_ = (o.backward || !M::kChartCrossesHorizon) ? m.capture_radius() : m.horizon_radius();
      // Seed RK4: the fixed base step is halved (powers of two) until it is at most kappa times the
      // distance to the centre, kappa = tol^(1/4) (global error ~ kappa^4).
      if constexpr (!S::kAdaptive) kappa_ = std::min(0.1, std::max(1e-4, std::pow(o.tol, 0.25)));
      const double limit = m.escape_limit();
      flat_far_ = !(limit > 0.0);
      esc_ = flat_far_ ? o.escape_radius : std::min(o.escape_radius, limit);
      target_ = esc_;
      escaped_ = false;
      if (m.radius(y) >= esc_ && moving_outward(m, y)) {  // starts outside, moving out
        res.sheet = m.chart_to_user(y, sheet, escape_pos_);
        escaped_ = true;
        target_ = tail_target(y);
        if (m.radius(y) >= target_) return finish_escaped(y);
      }
      r_ = m.radius(y);
      // Traced back from inside a horizon (a falling camera), every ray moves outward: light that fell in
      // crosses the horizon within a few horizon radii of coordinate time; the rest creeps up to it from
      // below as t -> -infinity (it came from the hole's own past: none in a hole formed by collapse) and
      // ends as "horizon" once it has spent 20 horizon radii of coordinate time there.
      stuck_t_ = -INFINITY;
      horizon_r_ = m.horizon_radius();
      if (o.backward && r_ < horizon_r_) stuck_t_ = y[0] - 20.0 * horizon_r_;
      // Adaptive steppers start at the largest step allowed and let the error control cut it down: a
      // rejected first attempt is cheaper than the 3-4 steps of growing from a small guess (16 % fewer
      // steps in a curved room, whose segments are short).
      h = S::kAdaptive ? max_step(r_) : rk4_step_for(r_);
      if (S::kAdaptive && first_step > 0.0) h = std::min(h, first_step);
      log_err_prev = kLogErrFloor;
      monitor_every_ = o.monitor_every > 0 ? o.monitor_every : (track || o.tol < 1e-8) ? 1 : 4;
      last_rejected_ = false;
      reinit_ = false;
      attempts_ = 0;
      return true;
    }
  }

  // Counts the next step attempt; false (the ray has ended) once the budget is spent.
  bool next() {
    if (attempts_ >= o_->max_steps) {
      if (escaped_) finish_escaped(y);
      else finish(kMaxSteps, y);
      return false;
    }
    ++attempts_;
    return true;
  }

  // Takes the result of st.attempt(m, y, h, tol, ynew) with scaled error e: rejects it (smaller h),
  // or accepts it, checks surfaces, horizon, escape and the conserved quantities, and sets up the
  // next attempt. Returns false when the ray has ended (its RayResult is complete).
  bool advance(S& st, double e, const double ynew[8]) {
    StepFactors<double> f{0.0, 0.0, 0.0};
    if constexpr (S::kAdaptive) {  // only the factor this step uses (the same bits as step_factors)
      f.log_e = step_log_error(e);
      if (e > 1.0) f.reject = reject_factor<S::kOrder>(f.log_e);
      else f.accept = accept_factor<S::kOrder>(f.log_e, log_err_prev);
    }
    return advance(st, e, f, ynew);
  }

  // The same, with the step factors of e computed already (by a batch, for all its rays).
  bool advance(S& st, double e, const StepFactors<double>& f, const double ynew[8]) {
    const M& m = *m_;
    const TraceOptions& o = *o_;
    RayResult& res = *res_;
    double ys[8];
    const double h_min = 1e-12 * std::max(1.0, r_);
    if (!state_finite(ynew) || !std::isfinite(e)) {
      h *= 0.25;
      last_rejected_ = true;
      if (h < h_min) return finish(kNaN, y);
      return true;
    }
    if (S::kAdaptive && e > 1.0) {
      h *= std::max(0.2, f.reject);
      last_rejected_ = true;
      if (h < h_min) return finish(kNaN, y);
      return true;
    }
    const HamiltonianParts hp = hamiltonian_parts_from_rhs(ynew, st.derivative_new());
    const double herr = hp.abs2h / std::max(h_scale_, hp.mag);
    if (!(herr <= o.max_drift)) {
      // Conserved-quantity monitor: retry smaller; a ray that cannot satisfy it is marked.
      h *= 0.5;
      last_rejected_ = true;
      if (h < h_min || (!S::kAdaptive && h < o.rk4_step * 1e-3)) return finish(kInvariantViolation, y);
      return true;
    }
    // Accepted step from y to ynew.
    ++res.n_steps;
    if (res.n_steps == 1) res.first_step = h;
    res.last_step = h;
    h_scale_ = std::max(h_scale_, hp.mag);
    if constexpr (Surf::kActive) {
      // Surface hit: located on the dense output; the state there from a full-order step, or the dense
      // output itself where the surfaces accept it (kDenseEnd) and the stepper's is as accurate as its step.
      double theta;
      int prim;
      if (surfaces_ && surfaces_->find(st, y, ynew, h, sheet_, theta, prim)) {
        if constexpr (Surf::kDenseEnd && S::kAccurateDense)
          st.dense(y, ynew, h, theta, ys);
        else
          st.attempt(m, y, theta * h, o.tol, ys);
        const bool ok = monitor_at(ys);
        record(ys, lam_ + theta * h, theta * h);
        res.prim = prim;
        return finish(ok ? kHit : kInvariantViolation, ys);
      }
    }
    const double r_new = m.radius(ynew);
    // Horizon: locate the crossing r = r_h on the dense output so the path ends on the horizon.
    // Traced back from below the capture radius (a falling camera), a ray is lost as soon as it moves
    // inward there: inside the photon sphere light moving inward never turns.
    if (r_new < r_h_ && r_ < r_h_ && r_new < r_) {
      const bool ok = monitor_at(ynew);
      record(ynew, lam_ + h, h);
      return finish(ok ? kHorizon : kInvariantViolation, ynew);
    }
    if (r_new < r_h_ && r_ >= r_h_) {
      auto dr = [&](double t) {
        st.dense(y, ynew, h, t, ys);
        return m.radius(ys) - r_h_;
      };
      const double hi = crossing(dr, 0.0, r_ - r_h_, 1.0, r_new - r_h_, 1e-14, 1e-13 * std::max(1.0, r_h_));
      // The crossing is found on the dense output; the state there comes from a full-order step.
      st.attempt(m, y, hi * h, o.tol, ys);
      const bool ok = monitor_at(ys);
      record(ys, lam_ + hi * h, hi * h);
      return finish(ok ? kHorizon : kInvariantViolation, ys);
    }
    // Escape: moving outward beyond the escape radius. The final position is the crossing of the
    // escape sphere (located on the dense output); the direction keeps integrating, unrecorded, out
    // to the radius where the Born tail's second-order error ~ 10 l^2 b / R^3 is below tol (cheap
    // for adaptive steppers, whose steps grow with r).
    if (r_new >= target_ && moving_outward(m, ynew)) {
      if (!escaped_) {
        double frac = 1.0;
        if (r_ < esc_) {
          const double R = esc_;
          auto dr = [&](double t) {
            st.dense(y, ynew, h, t, ys);
            return m.radius(ys) - R;
          };
          const double hi = crossing(dr, 0.0, r_ - R, 1.0, r_new - R, 1e-14, 1e-13 * R);
          frac = hi;
          st.attempt(m, y, hi * h, o.tol, ys);  // full-order state at the crossing
          reinit_ = true;                        // the trial step overwrote the stepper's stages
        } else {
          for (int i = 0; i < 8; ++i) ys[i] = ynew[i];
        }
        if (!monitor_at(ys)) return finish(kInvariantViolation, ys);
        record(ys, lam_ + frac * h, frac * h);
        res.sheet = m.chart_to_user(ys, sheet_, escape_pos_);
        escaped_ = true;
        target_ = tail_target(ys);
      }
      if (r_new >= target_) {
        monitor(ynew, hp, herr);  // the end state counts in the drift; the check ran at the crossing
        return finish_escaped(ynew);
      }
    }
    bool ok = true;
    if (monitor_every_ == 1 || res.n_steps % monitor_every_ == 0) {
      ok = monitor(ynew, hp, herr);
    } else {
      drift_[0] = reported_[0] = herr;
      res.drift[0] = res.drift_scaled[0] = std::max(res.drift_scaled[0], herr);
    }
    lam_ += h;
    if (!escaped_) record(ynew, lam_, h);
    st.accept();
    for (int i = 0; i < 8; ++i) y[i] = ynew[i];
    if (!ok) return finish(kInvariantViolation, y);
    if (y[0] < stuck_t_ && r_new < horizon_r_) return finish(kHorizon, y);
    r_ = r_new;
    if (m.normalize_chart(y, sheet_)) {
      st.init(m, y);
      r_ = m.radius(y);
    } else if (reinit_) {
      st.init(m, y);
    }
    reinit_ = false;
    if constexpr (S::kAdaptive) {
      // PI step-size control (step_factors).
      double fac = std::min(5.0, std::max(0.2, f.accept));
      if (last_rejected_) fac = std::min(fac, 1.0);
      h *= fac;
      log_err_prev = e >= 1e-4 ? f.log_e : kLogErrFloor;  // log(max(e, 1e-4))
      h = std::min(h, max_step(r_));
    } else {
      h = rk4_step_for(r_);
    }
    last_rejected_ = false;
    return true;
  }

 private:
  double herr_of(const HamiltonianParts& hp) {
    h_scale_ = std::max(h_scale_, hp.mag);
    return h_scale_ > 0.0 ? hp.abs2h / h_scale_ : 0.0;
  }

  void record(const double* ys, double lam_s, double hs) {
    if (!track_) return;
    const M& m = *m_;
    double pos[3];
    const int sh = m.chart_to_user(ys, sheet_, pos);
    track_->xyz.insert(track_->xyz.end(), pos, pos + 3);
    track_->cols.push_back(lam_s);
    track_->cols.push_back(ys[0]);
    track_->cols.push_back(m.radius(ys));
    track_->cols.push_back(hs);
    for (int k = 0; k < K; ++k) track_->cols.push_back(reported_[k]);
    for (int k = 1; k < K; ++k) track_->cols.push_back(drift_[k]);
    track_->cols.push_back(energy0_ > 0.0 ? local_energy(m, ys) / energy0_ : 0.0);
    track_->cols.push_back(double(sh));
  }

  // Ends a ray that did not escape: its direction is the coordinate direction of motion.
  bool finish(int status, const double* ys) {
    RayResult& res = *res_;
    res.status = status;
    for (int i = 0; i < 8; ++i) res.y[i] = ys[i];
    res.sheet = m_->chart_to_user(ys, sheet_, res.pos);
    double f[8];
    m_->rhs(ys, f);
    const double n = std::sqrt(f[1] * f[1] + f[2] * f[2] + f[3] * f[3]);
    for (int i = 0; i < 3; ++i) res.dir[i] = (n > 0.0 && std::isfinite(n)) ? f[1 + i] / n : 0.0;
    if (!state_finite(ys)) {
      for (int i = 0; i < 3; ++i) res.pos[i] = res.dir[i] = 0.0;
    }
    return false;
  }

  bool finish_escaped(const double* ys) {
    RayResult& res = *res_;
    res.status = kEscaped;
    for (int i = 0; i < 8; ++i) res.y[i] = ys[i];
    if (flat_far_) {
      asymptotic_direction(*m_, ys, res.dir);
    } else {  // no flat infinity to go to: the direction of motion at the escape sphere
      double f[8];
      m_->rhs(ys, f);
      const double n = std::sqrt(f[1] * f[1] + f[2] * f[2] + f[3] * f[3]);
      for (int i = 0; i < 3; ++i) res.dir[i] = n > 0.0 ? f[1 + i] / n : 0.0;
    }
    for (int i = 0; i < 3; ++i) res.pos[i] = escape_pos_[i];
    return false;
  }

  // Evaluates the conserved quantities at ys (H's parts there hp, its relative error herr) and updates
  // the running maxima; false on violation.
  bool monitor(const double* ys, const HamiltonianParts& hp, double herr) {
    m_->conserved(ys, hp, inv_, mag_);
    drift_[0] = reported_[0] = herr;
    bool ok = true;
    for (int k = 1; k < K; ++k) {
      scale_[k] = std::max(scale_[k], mag_[k]);
      // Once X0 is negligible against the terms seen so far (Lz of a ray leaving the axis), the
      // integration error, which scales with those terms, makes its relative drift meaningless.
      relative_[k] = relative_[k] && std::fabs(inv0_[k]) >= kNegligibleInvariant * scale_[k];
      const double change = std::fabs(inv_[k] - inv0_[k]);
      drift_[k] = change / scale_[k];
      reported_[k] = relative_[k] ? change / std::fabs(inv0_[k]) : drift_[k];
      if (!(drift_[k] <= o_->max_drift)) ok = false;
    }
    for (int k = 0; k < K; ++k) {
      res_->drift_scaled[k] = std::max(res_->drift_scaled[k], drift_[k]);
      res_->drift[k] = std::max(res_->drift[k], reported_[k]);
    }
    return ok;
  }

  bool monitor_at(const double* ys) {
    const HamiltonianParts hp = hamiltonian_parts(*m_, ys);
    const double herr = herr_of(hp);
    return monitor(ys, hp, herr);
  }

  // Largest step of the adaptive steppers at radius r: half the distance to the centre (at least the
  // strong-field scale), so no step jumps across the strong field.
  double max_step(double r) const { return 0.5 * std::max(r, m_->length_scale()); }

  double rk4_step_for(double r) const {
    double hs = o_->rk4_step;
    while (hs > kappa_ * r && hs > 1e-12) hs *= 0.5;
    return hs;
  }

  // Radius beyond which the Born tail of asymptotic_direction is accurate to tol for this ray.
  // Where an escaped ray's integration ends: on to the Born tail's radius where infinity is flat, at the
  // escape sphere itself where it is not.
  double tail_target(const double* ys) const { return flat_far_ ? std::max(esc_, tail_radius(ys)) : esc_; }

  double tail_radius(const double* ys) const {
    const M& m = *m_;
    const double ell = m.length_scale();
    double f[8];
    m.rhs(ys, f);
    const double cx = ys[2] * f[3] - ys[3] * f[2], cy = ys[3] * f[1] - ys[1] * f[3], cz = ys[1] * f[2] - ys[2] * f[1];
    const double v = std::sqrt(f[1] * f[1] + f[2] * f[2] + f[3] * f[3]);
    const double b = std::max(ell, std::sqrt(cx * cx + cy * cy + cz * cz) / v);
    return std::cbrt(10.0 * ell * ell * b / o_->tol);
  }

  static inline const double kLogErrFloor = fast_log(1e-4);
  const M* m_ = nullptr;
  const TraceOptions* o_ = nullptr;
  RayResult* res_ = nullptr;
  Track* track_ = nullptr;
  Surf* surfaces_ = nullptr;
  int sheet_ = 1;
  double inv0_[K], scale_[K], inv_[K], drift_[K], reported_[K], mag_[K];  // drift_: term-scaled
  bool relative_[K];  // X0 is not negligible: the reported drift is relative to |X0|
  double h_scale_ = 0.0, lam_ = 0.0, energy0_ = 0.0;
  double r_h_ = 0.0, kappa_ = 0.1, target_ = 0.0, r_ = 0.0;
  double stuck_t_ = -INFINITY, horizon_r_ = 0.0;  // rays traced back from inside the horizon (start())
  double esc_ = 0.0;      // the escape radius: the trace's, or the metric's escape_limit if smaller
  bool flat_far_ = true;  // asymptotically flat: an escaped ray integrates on to the Born tail's radius
  bool escaped_ = false;  // crossed the escape sphere; still integrating for the direction
  double escape_pos_[3] = {0, 0, 0};
  bool last_rejected_ = false, reinit_ = false;
  long attempts_ = 0;
  int monitor_every_ = 1;
};

// Integrates one ray from state y (chart coordinates, covariant momentum) on `sheet`; y is left at the
// last accepted state.
template <class M, class S, class Surf = NoSurfaces>
void integrate_ray(const M& m, double y[8], int sheet, const TraceOptions& o, RayResult& res, Track* track,
                   Surf* surfaces = nullptr, double first_step = 0.0) {
  GeodesicRay<M, S, Surf> ray;
  if (ray.begin(m, y, sheet, o, res, track, surfaces, first_step)) {
    S st;
    st.init(m, ray.y);
    double ynew[8];
    while (ray.next()) {
      const double e = st.attempt(m, ray.y, ray.h, o.tol, ynew);
      if (!ray.advance(st, e, ynew)) break;
    }
  }
  for (int i = 0; i < 8; ++i) y[i] = ray.y[i];
}

}  // namespace wv
