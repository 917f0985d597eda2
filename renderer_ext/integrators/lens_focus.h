// Where a hole focuses a light onto a vertex: a share of the lens connection's light points drawn about the point
// of the light's plane that lies straight behind the centre, as densely as the lens magnifies them.
//
// Seen from a diffuse vertex A, a light point B beyond the centre O has images whose magnification grows without
// bound as B nears the line from A through O (an Einstein ring where B is on it). What B's images bring to A,
// W(B) = sum of cos(theta) |dOmega_A / dA_B| (lens_connection.h), grows alike, so light points drawn uniformly
// by area bring light that varies as W does, and the few that land near B* (where that line meets the light's
// plane) carry most of it: the floor under a hole that has a lamp above it, lit by the lamp's magnified ring, was
// the noisiest part of fig07 and fig10d. Seen from fig07's floor at (0, -10, -50), W's variance over the lamp by
// area is 1.75 of its mean squared (by the lens map's exact weights on an 80 x 80 grid of the lamp).
//
// The thin point lens's total magnification of a source at u Einstein radii from the axis is
// mu(u) = (u^2 + 2) / (u sqrt(u^2 + 4)), and mu(u) u has the primitive F(u) = u sqrt(u^2 + 4) / 2, whose inverse
// is u^2 = 2 (sqrt(1 + F^2) - 1). The focus draws an angle t about B* over the angles at which the light lies (all
// round where B* is inside the light's outline), then a distance rho along that direction with density
// proportional to mu(rho / rho_E) rho over the parts of the ray that lie on the light (PlanarLight::clip), by
// inverting F: no draw falls off the light. The angle is drawn from kBins equal bins, each as likely as the sum
// G(t) of F's increments over the ray's parts on the light along its middle ray (what the lens magnifies that
// way), uniformly within the bin: drawn evenly instead, the short rays from a B* near the light's edge to that
// edge were drawn as often as the long ones across the light, and the density was up to ~10x off the
// magnification's shape (the light sample's variance from (0, -10, -50) in fig07: 0.15 of its mean squared at
// share 0.5 and 0.32 at share 1, against 0.010 at 0.9 with the bins; with B* at the lamp's centre 0.10 and 0.010).
// The density per unit area at a light point at distance rho from B* in direction t (in bin j of probability P_j
// and width span / kBins) is mu(u) P_j kBins / (span rho_E^2 G(t)), with u = rho / rho_E and span the angles'
// range: mu's shape within each bin. The Einstein radius in the light's plane is the thin lens's,
// rho_E = sqrt(4 M D_OB D_AB / D_AO) (A the observer, the light the source). The rest of the draws stay uniform by
// area (or the Kerr proposal's draws with their margin), and the pdf of any light point is the mixture's, a
// function of A and B alone, so both strategies of the lens connection agree on it and the estimator stays
// unbiased.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/vec3.h"
#include "integrators/lens_proposal.h"

namespace wv {

// The focus's share of a light's draws where it applies (where B* lies within kFocusReach Einstein radii of the
// light): the rest, drawn by area, bound the weights where the point lens's magnification is not the strong
// field's. The light sample's variance from fig07's floor (over its mean squared, header above) at shares 0.5,
// 0.7, 0.9 and 1: 0.099, 0.032, 0.009, 0.011 at (0, -10, -50), 0.028, 0.007, 0.005, 0.011 at (17, 0, -50) (B*
// just off the lamp). fig07 at 48 x 36 x 16 (24 seeds, 2048-spp reference): relative MSE 0.00737 at 0.5, 0.00714
// at 0.8, 0.00710 at 0.9, 0.00713 at 0.95 (0.00773 before the bins); fig10d and the Kerr-Newman room the same
// within their noise at 0.5 and 0.9.
inline constexpr double kFocusShare = 0.9;
// The focus applies where B* lies within this many Einstein radii of the light: farther, the light's images are
// magnified about alike all over it (W varies by 5 % of its mean squared over a test room's lamp seen from the
// floor beside the hole, where the thin lens's mu overstates the strong field's magnification) and draws gathered
// towards B*'s side of it only make their weights uneven: the test room's floor near the camera had 1.5-3.5x the
// variance with the focus reaching an Einstein radius beyond the light, the floor round the hole 2-8x with half
// one. With 0.15, the floor seen from above has 0.51x the variance of draws by area alone (0.58x at 0.5, 0.53x
// with B* on the light only); fig07 and fig10d are the same at all three. With the angles' bins (and share 0.9)
// fig07 is the same at 0.15, 0.6 and 1.5 (relative MSE 0.00712, 0.00710, 0.00710).
inline constexpr double kFocusReach = 0.15;

class LensFocus {
 public:
  LensFocus() = default;

  // The focus of light L (its drawn outline: the light, or the Kerr proposal's grown light) seen from vertex a
  // (user frame, the centre at the origin) by a lens of mass `mass` (0: none): inactive where the line from a
  // through the centre meets L's plane before the centre or not at all, or farther than kFocusReach Einstein radii
  // from L. L must outlive the focus (it keeps a pointer: the connection's own lights; not a temporary).
  LensFocus(double mass, V3 a, const PlanarLight& L) : L_(&L) {
    if (!(mass > 0.0)) return;
    const V3 n = L.normal();
    const double den = dot(a, n);  // a + s (0 - a) meets the plane at s = (a - origin) . n / (a . n)
    if (!(std::fabs(den) > 0.0)) return;
    const double s = dot(a - L.origin(), n) / den;
    if (!(s > 1.0) || !std::isfinite(s)) return;
    centre_ = a * (1.0 - s);
    const double d_ao = length(a), d_ob = length(centre_);
    rho_e_ = std::sqrt(4.0 * mass * d_ob * (d_ao + d_ob) / d_ao);
    const V3 to_light = L.centre() - centre_;
    const double off = length(to_light), reach = L.reach();
    if (!(reach > 0.0) || !(rho_e_ > 0.0) || !(distance(L) < kFocusReach * rho_e_)) return;
    if (inside(L)) {
      basis_around(n, e1_, e2_);
      t0_ = 0.0;
      span_ = kTwoPi;
    } else {  // the range of angles about B* at which the light lies, about the direction to its centre
      e1_ = to_light / off;
      e2_ = cross(n, e1_);
      double lo = 0.0, hi = 0.0;
      if (L.is_disk) {
        hi = std::asin(std::min(1.0, reach / off));
        lo = -hi;
      } else {
        const Quad& q = L.quad;
        for (V3 c : {q.corner, q.corner + q.eu, q.corner + q.ev, q.corner + q.eu + q.ev}) {
          const double t = std::atan2(dot(c - centre_, e2_), dot(c - centre_, e1_));
          lo = std::min(lo, t);
          hi = std::max(hi, t);
        }
      }
      t0_ = lo;
      span_ = hi - lo;
    }
    if (!(span_ > 0.0)) return;
    // The angles' bins: each as likely as G along its middle ray (cdf_: their cumulative probabilities).
    double acc = 0.0;
    cdf_[0] = 0.0;
    for (int j = 0; j < kBins; ++j) {
      acc += weight_along(direction(t0_ + span_ * (j + 0.5) / kBins));
      cdf_[j + 1] = acc;
    }
    if (!(acc > 0.0)) return;
    for (int j = 1; j <= kBins; ++j) cdf_[j] /= acc;
    cdf_[kBins] = 1.0;
    share_ = kFocusShare;
  }

  LensFocus(double, V3, PlanarLight&&) = delete;  // (a temporary light would dangle)

  bool active() const { return share_ > 0.0; }
  double share() const { return share_; }

  // The point drawn from (u1, u2) in [0, 1)^2; false where the ray at that angle misses the light (a disk's
  // range of angles is its bounding circle's).
  bool point(double u1, double u2, V3& x) const {
    int j = 0;
    while (j + 1 < kBins && u2 >= cdf_[j + 1]) ++j;
    const double in_bin = (u2 - cdf_[j]) / std::max(cdf_[j + 1] - cdf_[j], 1e-300);
    const V3 d = direction(t0_ + span_ * (j + std::min(std::max(in_bin, 0.0), 1.0)) / kBins);
    double a[2], b[2];
    const int k = parts(d, a, b);
    const double total = increments(a, b, k);
    if (!(total > 0.0)) return false;
    double y = u1 * total;
    int i = 0;
    for (; i + 1 < k && y >= F(b[i]) - F(a[i]); ++i) y -= F(b[i]) - F(a[i]);  // (i read, then moved on)
    const double f = std::min(F(a[i]) + y, F(b[i]));
    x = centre_ + d * (rho_e_ * std::sqrt(2.0 * f * f / (std::sqrt(1.0 + f * f) + 1.0)));  // u = F^-1(f)
    return true;
  }

  // The focus's part of the draws' density per unit area at point x of the light: share mu(u) / (span rho_E^2
  // sum dF) (0 where the focus is inactive or never draws x).
  double density(V3 x) const {
    if (!active()) return 0.0;
    const V3 v = x - centre_;
    const double rho = length(v);
    if (!(rho > 0.0)) return 0.0;
    double t = std::atan2(dot(v, e2_), dot(v, e1_)) - t0_;
    if (span_ >= kTwoPi && t < 0.0) t += kTwoPi;  // (all round B* inside the light: every angle is drawn)
    if (t < 0.0 || t > span_) return 0.0;
    const int j = std::min(kBins - 1, int(t / span_ * kBins));
    const double angle_density = (cdf_[j + 1] - cdf_[j]) * kBins / span_;
    double a[2], b[2];
    const int k = parts(v / rho, a, b);
    const double total = increments(a, b, k);
    bool on = false;
    for (int i = 0; i < k; ++i) on = on || (rho >= rho_e_ * a[i] && rho <= rho_e_ * b[i]);
    if (!on || !(total > 0.0)) return 0.0;
    const double u = rho / rho_e_;
    const double mu = (u * u + 2.0) / (u * std::sqrt(u * u + 4.0));
    return share_ * angle_density * mu / (rho_e_ * rho_e_ * total);
  }

 private:
  // F(u) = u sqrt(u^2 + 4) / 2, the primitive of mu(u) u.
  static double F(double u) { return 0.5 * u * std::sqrt(u * u + 4.0); }

  // The sum of F's increments over the k parts [a_i, b_i] of a ray (parts()).
  static double increments(const double* a, const double* b, int k) {
    double total = 0.0;
    for (int i = 0; i < k; ++i) total += F(b[i]) - F(a[i]);
    return total;
  }

  // G: that sum over the parts of the ray from B* along unit direction d that lie on the light.
  double weight_along(V3 d) const {
    double a[2], b[2];
    const int k = parts(d, a, b);
    return increments(a, b, k);
  }

  V3 direction(double t) const { return e1_ * std::cos(t) + e2_ * std::sin(t); }

  // The distance from B* to the light's outline (a disk's outer circle; 0 inside).
  double distance(const PlanarLight& L) const {
    if (inside(L)) return 0.0;
    if (L.is_disk) return std::max(0.0, length(centre_ - L.disk.center) - L.reach());
    const Quad& q = L.quad;
    auto to_edge = [&](V3 p, V3 e) {  // to the segment p + t e, t in [0, 1]
      const double t = std::clamp(dot(centre_ - p, e) / dot(e, e), 0.0, 1.0);
      return length(centre_ - (p + e * t));
    };
    return std::min({to_edge(q.corner, q.eu), to_edge(q.corner, q.ev), to_edge(q.corner + q.eu, q.ev),
                     to_edge(q.corner + q.ev, q.eu)});
  }

  // Whether B* lies inside the light's outline (a disk's outer circle).
  bool inside(const PlanarLight& L) const {
    if (!L.is_disk) return L.contains(centre_);
    return disk_radius2(L.disk, centre_) <= L.disk.r_out * L.disk.r_out;
  }

  // The parts [a, b] (in Einstein radii) of the ray from B* along unit direction d that lie on the light.
  int parts(V3 d, double a[2], double b[2]) const {
    double lo[2], hi[2];
    const int n = L_->clip(centre_, d, lo, hi);
    int k = 0;
    for (int i = 0; i < n; ++i) {
      if (!(hi[i] > 0.0)) continue;
      a[k] = std::max(lo[i], 0.0) / rho_e_;
      b[k] = hi[i] / rho_e_;
      if (b[k] > a[k]) ++k;
    }
    return k;
  }

  const PlanarLight* L_ = nullptr;
  V3 centre_, e1_, e2_;
  double rho_e_ = 0.0, t0_ = 0.0, span_ = 0.0, share_ = 0.0;
  static constexpr int kBins = 32;  // the angles' bins
  double cdf_[kBins + 1] = {};
};

}  // namespace wv
