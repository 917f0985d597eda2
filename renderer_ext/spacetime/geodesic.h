// Integrating one null geodesic: stepping, conserved-quantity monitoring, termination status,
// horizon/escape crossings located on the dense output, asymptotic directions, recording.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/root.h"
#include "spacetime/frame.h"
#include "spacetime/metric.h"

namespace wv {

enum RayStatus : int8_t {
  kEscaped = 0,
  kHit = 1,
  kHorizon = 2,
  kMaxSteps = 3,
  kInvariantViolation = 4,
  kNaN = 5,
};

struct TraceOptions {
  double tol = 1e-9;            // relative + absolute local error per step (adaptive steppers)
  long max_steps = 100000;      // budget of step attempts, accepted or rejected
  double escape_radius = 1e3;   // rays moving outward beyond this radius have escaped
  double max_drift = 1e-6;      // largest allowed relative drift of any conserved quantity
  double rk4_step = 1.0;        // base (far-field) step of the seed RK4 method
  bool record = false;          // keep the polyline and per-point data
  bool backward = false;        // past-directed ray (camera rays): captured at the metric's capture radius
};

struct RayResult {
  int status = kNaN;
  double pos[3] = {0, 0, 0};  // final position, user frame
  double dir[3] = {0, 0, 0};  // asymptotic direction (escaped) or coordinate direction of motion
  int sheet = 1;
  long n_steps = 0;
  double drift[kMaxInvariants] = {0, 0, 0, 0, 0, 0};  // max relative drift along the ray; [0] is |H|
  double y[8] = {0, 0, 0, 0, 0, 0, 0, 0};  // final chart state (position and covariant momentum)
  int prim = -1;                           // surface hit (status kHit): the scene primitive
};

// Surfaces tested along each accepted step (none for plain geodesics). A surface set provides
//   static constexpr bool kActive = true;
//   template <class S> bool find(const S& stepper, const double* y, const double* ynew, double h, int sheet,
//                                double& theta, int& prim);
// returning the fraction theta of the step at which the path first crosses a surface.
struct NoSurfaces {
  static constexpr bool kActive = false;
};

// One recorded polyline: xyz (3 per point, user frame) and `columns` values per point:
// affine_param, coord_time, r, step_size, hamiltonian_err, drift of invariants 1..K-1, redshift
// (photon frequency seen by the local static observer / ZAMO over the one at the ray's start), sheet.
struct Track {
  std::vector<double> xyz;
  std::vector<double> cols;
};

template <class M>
constexpr int track_columns() {
  return 5 + (M::kNumInvariants - 1) + 2;
}

// Gauss-Legendre rule on [0, 1], nodes by Newton iteration on the Legendre recurrence.
template <int N>
struct GaussLegendre {
  double x[N], w[N];
  GaussLegendre() {
    for (int i = 0; i < N; ++i) {
      double z = std::cos(M_PI * (i + 0.75) / (N + 0.5)), dp = 1.0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1.0, p1 = z;
        for (int k = 2; k <= N; ++k) {
          const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = N * (z * p1 - p0) / (z * z - 1.0);
        const double dz = p1 / dp;
        z -= dz;
        if (std::fabs(dz) < 1e-16) break;
      }
      x[i] = 0.5 * (1.0 - z);
      w[i] = 1.0 / ((1.0 - z * z) * dp * dp);
    }
  }
};

inline const GaussLegendre<16>& gauss_legendre16() {
  static const GaussLegendre<16> rule;
  return rule;
}

// Direction of motion at infinity of an outgoing ray at state y. The momentum change still to come is
// integrated along the straight continuation x + v s (first-order Born approximation, 16-point
// Gauss-Legendre in u = c / (c + s)), so the error is second order in the field left beyond y:
// O(M^2 b / r^3) for a mass M, instead of the O(M b / r^2) of taking the local direction.
template <class M>
void asymptotic_direction(const M& m, const double y[8], double dir[3]) {
  double f[8];
  m.rhs(y, f);
  const double v[3] = {f[1], f[2], f[3]};
  const double vn = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  const double r0 = std::sqrt(y[1] * y[1] + y[2] * y[2] + y[3] * y[3]);
  double p[3] = {y[5], y[6], y[7]};
  if (vn > 0.0 && r0 > 0.0) {
    const double c = r0 / vn;
    const auto& gl = gauss_legendre16();
    double ys[8], fs[8];
    for (int q = 0; q < 16; ++q) {
      const double u = gl.x[q], s = c * (1.0 - u) / u, w = gl.w[q] * c / (u * u);
      for (int i = 0; i < 8; ++i) ys[i] = y[i];
      for (int i = 0; i < 3; ++i) ys[1 + i] += v[i] * s;
      m.rhs(ys, fs);
      for (int i = 0; i < 3; ++i) p[i] += w * fs[5 + i];
    }
  }
  const double pn = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
  for (int i = 0; i < 3; ++i) dir[i] = pn > 0.0 ? p[i] / pn : 0.0;
}

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
      for (int j = 1; j < M::kNumInvariants; ++j) track->cols.push_back(0.0);
      track->cols.push_back(1.0);  // no shift in flat space
      track->cols.push_back(double(sheet));
    }
  }
  (void)m;
}

// Integrates one ray from state y (chart coordinates, covariant momentum) on `sheet`.
template <class M, class S, class Surf = NoSurfaces>
void integrate_ray(const M& m, double y[8], int sheet, const TraceOptions& o, RayResult& res, Track* track,
                   Surf* surfaces = nullptr) {
  if constexpr (M::kFlat) {
    straight_ray(m, y, sheet, o, res, track);
    return;
  } else {
    constexpr int K = M::kNumInvariants;
    double inv0[K], scale[K], inv[K], drift[K], mag[K];
    m.invariants(y, inv0);
    m.invariant_scales(y, inv0, scale);
    // Like H below, each conserved quantity's drift is measured against the largest size of the terms
    // it is computed from along the ray (at least its scale at the start): where momenta grow large
    // (backward rays near a horizon) the cancellation in those terms limits what can be conserved.
    for (int k = 0; k < K; ++k) mag[k] = 0.0;
    m.conserved(y, inv, mag);
    for (int k = 1; k < K; ++k) scale[k] = std::max(scale[k], mag[k]);
    for (int k = 0; k < K; ++k) drift[k] = 0.0;
    // H is measured relative to the largest size its terms had along the ray: the rounding and
    // truncation errors committed where the coordinate momenta were large (e.g. an outgoing ray
    // starting just outside a horizon) do not grow as the momenta shrink, and no step-size
    // reduction later could remove them.
    double h_scale = 0.0;
    auto herr_of = [&](const HamiltonianParts& hp) {
      h_scale = std::max(h_scale, hp.mag);
      return h_scale > 0.0 ? hp.abs2h / h_scale : 0.0;
    };
    auto herr_at = [&](const double* ys) { return herr_of(hamiltonian_parts(m, ys)); };
    drift[0] = herr_at(y);
    for (int k = 0; k < K; ++k) res.drift[k] = drift[k];
    res.n_steps = 0;
    double lam = 0.0;

    const double energy0 = track ? local_energy(m, y) : 0.0;
    auto record = [&](const double* ys, double lam_s, double h) {
      if (!track) return;
      double pos[3];
      const int sh = m.chart_to_user(ys, sheet, pos);
      track->xyz.insert(track->xyz.end(), pos, pos + 3);
      track->cols.push_back(lam_s);
      track->cols.push_back(ys[0]);
      track->cols.push_back(m.radius(ys));
      track->cols.push_back(h);
      for (int k = 0; k < K; ++k) track->cols.push_back(drift[k]);
      track->cols.push_back(energy0 > 0.0 ? local_energy(m, ys) / energy0 : 0.0);
      track->cols.push_back(double(sh));
    };
    // Ends a ray that did not escape: its direction is the coordinate direction of motion.
    auto finish = [&](int status, const double* ys) {
      res.status = status;
      for (int i = 0; i < 8; ++i) res.y[i] = ys[i];
      res.sheet = m.chart_to_user(ys, sheet, res.pos);
      double f[8];
      m.rhs(ys, f);
      const double n = std::sqrt(f[1] * f[1] + f[2] * f[2] + f[3] * f[3]);
      for (int i = 0; i < 3; ++i) res.dir[i] = (n > 0.0 && std::isfinite(n)) ? f[1 + i] / n : 0.0;
      if (!state_finite(ys)) {
        for (int i = 0; i < 3; ++i) res.pos[i] = res.dir[i] = 0.0;
      }
    };
    // Evaluates the conserved quantities at ys and updates the running maxima; false on violation.
    auto monitor = [&](const double* ys, double herr) {
      m.conserved(ys, inv, mag);
      drift[0] = herr;
      bool ok = true;
      for (int k = 1; k < K; ++k) {
        scale[k] = std::max(scale[k], mag[k]);
        drift[k] = std::fabs(inv[k] - inv0[k]) / scale[k];
        if (!(drift[k] <= o.max_drift)) ok = false;
      }
      for (int k = 0; k < K; ++k) res.drift[k] = std::max(res.drift[k], drift[k]);
      return ok;
    };

    record(y, 0.0, 0.0);
    if (!state_finite(y)) return finish(kNaN, y);

    const double r_h = o.backward ? m.capture_radius() : m.horizon_radius();
    // Seed RK4: the fixed base step is halved (powers of two) until it is at most kappa times the
    // distance to the centre, kappa = tol^(1/4) (global error ~ kappa^4).
    const double kappa = std::min(0.1, std::max(1e-4, std::pow(o.tol, 0.25)));
    auto rk4_step_for = [&](double r) {
      double h = o.rk4_step;
      while (h > kappa * r && h > 1e-12) h *= 0.5;
      return h;
    };

    // Radius beyond which the Born tail of asymptotic_direction is accurate to tol for this ray.
    const double ell = m.length_scale();
    auto tail_radius = [&](const double* ys) {
      double f[8];
      m.rhs(ys, f);
      const double cx = ys[2] * f[3] - ys[3] * f[2], cy = ys[3] * f[1] - ys[1] * f[3], cz = ys[1] * f[2] - ys[2] * f[1];
      const double v = std::sqrt(f[1] * f[1] + f[2] * f[2] + f[3] * f[3]);
      const double b = std::max(ell, std::sqrt(cx * cx + cy * cy + cz * cz) / v);
      return std::cbrt(10.0 * ell * ell * b / o.tol);
    };
    double target = o.escape_radius;
    bool escaped = false;  // crossed the escape sphere; still integrating for the direction
    double escape_pos[3];
    auto finish_escaped = [&](const double* ys) {
      res.status = kEscaped;
      for (int i = 0; i < 8; ++i) res.y[i] = ys[i];
      asymptotic_direction(m, ys, res.dir);
      for (int i = 0; i < 3; ++i) res.pos[i] = escape_pos[i];
    };

    if (m.radius(y) >= o.escape_radius && moving_outward(m, y)) {  // starts outside, moving out
      res.sheet = m.chart_to_user(y, sheet, escape_pos);
      escaped = true;
      target = std::max(o.escape_radius, tail_radius(y));
      if (m.radius(y) >= target) return finish_escaped(y);
    }

    S st;
    st.init(m, y);
    double r = m.radius(y);
    double h = S::kAdaptive ? 0.01 * std::max(r, m.length_scale()) : rk4_step_for(r);
    double log_err_prev = std::log(1e-4);
    bool last_rejected = false;
    bool reinit = false;
    long attempts = 0;
    double ynew[8], ys[8];
    while (true) {
      if (attempts >= o.max_steps) return escaped ? finish_escaped(y) : finish(kMaxSteps, y);
      ++attempts;
      const double h_min = 1e-12 * std::max(1.0, r);
      const double e = st.attempt(m, y, h, o.tol, ynew);
      if (!state_finite(ynew) || !std::isfinite(e)) {
        h *= 0.25;
        last_rejected = true;
        if (h < h_min) return finish(kNaN, y);
        continue;
      }
      if (S::kAdaptive && e > 1.0) {
        h *= std::max(0.2, 0.9 * std::pow(e, -1.0 / S::kOrder));
        last_rejected = true;
        if (h < h_min) return finish(kNaN, y);
        continue;
      }
      const HamiltonianParts hp = hamiltonian_parts_from_rhs(ynew, st.derivative_new());
      const double herr = hp.abs2h / std::max(h_scale, hp.mag);
      if (!(herr <= o.max_drift)) {
        // Conserved-quantity monitor: retry smaller; a ray that cannot satisfy it is marked.
        h *= 0.5;
        last_rejected = true;
        if (h < h_min || (!S::kAdaptive && h < o.rk4_step * 1e-3)) return finish(kInvariantViolation, y);
        continue;
      }
      // Accepted step from y to ynew.
      ++res.n_steps;
      h_scale = std::max(h_scale, hp.mag);
      if constexpr (Surf::kActive) {
        // Surface hit: located on the dense output, the state there from a full-order step.
        double theta;
        int prim;
        if (surfaces && surfaces->find(st, y, ynew, h, sheet, theta, prim)) {
          st.attempt(m, y, theta * h, o.tol, ys);
          monitor(ys, herr_at(ys));
          record(ys, lam + theta * h, theta * h);
          res.prim = prim;
          return finish(kHit, ys);
        }
      }
      const double r_new = m.radius(ynew);
      // Horizon: locate the crossing r = r_h on the dense output so the path ends on the horizon.
      if (r_new < r_h) {
        auto dr = [&](double t) {
          st.dense(y, ynew, h, t, ys);
          return m.radius(ys) - r_h;
        };
        const double hi = crossing(dr, 0.0, r - r_h, 1.0, r_new - r_h, 1e-14, 1e-13 * std::max(1.0, r_h));
        // The crossing is found on the dense output; the state there comes from a full-order step.
        st.attempt(m, y, hi * h, o.tol, ys);
        monitor(ys, herr_at(ys));
        record(ys, lam + hi * h, hi * h);
        return finish(kHorizon, ys);
      }
      // Escape: moving outward beyond the escape radius. The final position is the crossing of the
      // escape sphere (located on the dense output); the direction keeps integrating, unrecorded, out
      // to the radius where the Born tail's second-order error ~ 10 l^2 b / R^3 is below tol (cheap
      // for adaptive steppers, whose steps grow with r).
      if (r_new >= target && moving_outward(m, ynew)) {
        if (!escaped) {
          double frac = 1.0;
          if (r < o.escape_radius) {
            const double R = o.escape_radius;
            auto dr = [&](double t) {
              st.dense(y, ynew, h, t, ys);
              return m.radius(ys) - R;
            };
            const double hi = crossing(dr, 0.0, r - R, 1.0, r_new - R, 1e-14, 1e-13 * R);
            frac = hi;
            st.attempt(m, y, hi * h, o.tol, ys);  // full-order state at the crossing
            reinit = true;                        // the trial step overwrote the stepper's stages
          } else {
            for (int i = 0; i < 8; ++i) ys[i] = ynew[i];
          }
          if (!monitor(ys, herr_at(ys))) return finish(kInvariantViolation, ys);
          record(ys, lam + frac * h, frac * h);
          res.sheet = m.chart_to_user(ys, sheet, escape_pos);
          escaped = true;
          target = std::max(o.escape_radius, tail_radius(ys));
        }
        if (r_new >= target) return finish_escaped(ynew);
      }
      const bool ok = monitor(ynew, herr);
      lam += h;
      if (!escaped) record(ynew, lam, h);
      st.accept();
      for (int i = 0; i < 8; ++i) y[i] = ynew[i];
      if (!ok) return finish(kInvariantViolation, y);
      if (m.normalize_chart(y, sheet) || reinit) st.init(m, y);
      reinit = false;
      r = m.radius(y);
      if constexpr (S::kAdaptive) {
        // PI step-size control (Gustafsson; Hairer & Wanner's constants).
        constexpr double beta = 0.04, alpha = 1.0 / S::kOrder - 0.75 * beta;
        const double log_e = std::log(std::max(e, 1e-10));
        double fac = 0.9 * std::exp(beta * log_err_prev - alpha * log_e);
        fac = std::min(5.0, std::max(0.2, fac));
        if (last_rejected) fac = std::min(fac, 1.0);
        h *= fac;
        log_err_prev = std::log(std::max(e, 1e-4));
        h = std::min(h, 0.5 * std::max(r, m.length_scale()));
      } else {
        h = rk4_step_for(r);
      }
      last_rejected = false;
    }
  }
}

}  // namespace wv
