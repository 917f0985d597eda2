// The exact lens connection of Schwarzschild as a proposal in a spacetime that has no exact lens map (Kerr,
// whose metric declares the Schwarzschild map of the same mass as its lens proxy, and a mass for each orbit plane
// and sense: ProxyMass below). The light strategy draws a point B on a light by area and one of B's images in the
// proxy map, with the probabilities of lens_connection.h; the geodesic along that direction then follows the true
// metric and lands where it lands. Multiple importance sampling stays unbiased when both strategies evaluate the
// light strategy's density as a function of the direction alone. Here that function is
//
//   p(w) = P(light) cos(theta_w) / (area W(B_S(w)))   (with a margin: 1 / area the draws' density at B_S),
//
// where B_S(w) is the point at which the proxy orbit leaving the vertex along w first crosses the light
// (swept azimuth below orders * pi, the orders sampled), and W is the proxy map's weight sum of B_S's
// images, with p = 0 where the orbit crosses no light point first from its lit side. A light sample counts
// only if its own B is B_S of the direction it drew, so p is exactly the density of the samples that count.
// A BSDF ray that reaches the light in the true metric gets p of its direction whatever point it hit.
//
// The true images lie near the proxy's, not on them (in Kerr frame dragging moves them by up to about twice the
// spin length a at the light), and directions by which light arrives but whose proxy orbit misses the light have
// p = 0: there only BSDF sampling finds the light, one rare sample at its full weight (albedo times radiance). So
// the proposal sees each light grown by a margin all round in its plane (ProposalLight: the metric's
// lens_proxy_margin, else a twentieth of the light's size) and draws B on the light itself, or with probability
// kProposalMarginShare in the margin, each uniformly by area; p above then takes the draws' density at B_S in place
// of 1 / area, and a sample whose B lies in the margin counts where its true geodesic reaches the light. In fig10d
// (a = 0.9 M) 10 % of the direct light at the first diffuse vertices came by BSDF samples of p = 0 and made 76 % of
// that light's second moment; the margin took the room's error 33 % down at equal time (benchmarks/README.md).
//
// B_S(w): the orbit lies in the plane of the centre, the vertex and w (planar_orbit.h gives u = 1/R as an
// elliptic function of the swept azimuth phi). That plane meets the light's plane in a line, clipped to the
// light: a segment that subtends an interval of polar angles, once per turn. Along it the orbit meets the
// line where g(phi) = alpha cos phi + beta sin phi - delta u(phi) vanishes (alpha, beta: the light normal's
// components along the vertex's radial direction and the orbit's tangent; delta: the plane's offset), and
// the first root is found with a bound G on |g''| (from u'' = 3 M u^2 - u): a piece is empty when its end
// values share a sign and exceed G h^2 / 8, holds one root when its secant slope exceeds G h, and is
// halved otherwise.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/vec3.h"
#include "scene/light.h"
#include "scene/scene.h"
#include "spacetime/planar_orbit.h"

namespace wv {

// A planar light (quad or disk) as the proposal sees it: its plane and the segment a line in that plane keeps
// inside it.
struct PlanarLight {
  bool is_disk = false;
  Quad quad;  // (a quad light)
  Disk disk;  // (a disk light)

  V3 normal() const { return is_disk ? disk.normal : quad.normal; }
  V3 origin() const { return is_disk ? disk.center : quad.corner; }  // a point of its plane

  double area() const {
    return is_disk ? disk_area(disk) : quad.area;
  }

  // The same light grown by `margin` (user-frame length) all round in its plane: a quad's edges move out by it, a
  // disk's outer radius grows and its hole shrinks by it (in units of its axes).
  PlanarLight grown(double margin) const {
    PlanarLight g = *this;
    if (!(margin > 0.0)) return g;
    if (is_disk) {
      g.disk.r_out += margin;
      g.disk.r_in = std::max(0.0, g.disk.r_in - margin);
      return g;
    }
    const double lu = length(quad.eu), lv = length(quad.ev);
    // Each edge moves out along the in-plane normal to it: the corner by the sum of both offsets, expressed in the
    // (possibly skew) edge directions through the dual vectors.
    const V3 nu = normalize(quad.du), nv = normalize(quad.dv);  // in-plane normals of the v- and u-edges
    const double su = margin / dot(nu, quad.eu / lu), sv = margin / dot(nv, quad.ev / lv);
    const V3 eu = quad.eu * ((lu + 2.0 * su) / lu), ev = quad.ev * ((lv + 2.0 * sv) / lv);
    g.quad = make_quad(quad.corner - quad.eu * (su / lu) - quad.ev * (sv / lv), eu, ev);
    return g;
  }

  // Whether point x of its plane lies on it.
  bool contains(V3 x) const {
    if (!is_disk) {
      const double s = dot(x - quad.corner, quad.du), r = dot(x - quad.corner, quad.dv);
      return s >= 0.0 && s <= 1.0 && r >= 0.0 && r <= 1.0;
    }
    const double rho2 = disk_radius2(disk, x);
    return rho2 >= disk.r_in * disk.r_in && rho2 <= disk.r_out * disk.r_out;
  }

  // Its centre, and the radius of the smallest circle about it that holds it.
  V3 centre() const { return is_disk ? disk.center : quad.corner + (quad.eu + quad.ev) * 0.5; }
  double reach() const {
    if (is_disk) return disk.r_out * std::sqrt(std::max(dot(disk.axis_u, disk.axis_u), dot(disk.axis_v, disk.axis_v)));
    return 0.5 * std::max(length(quad.eu + quad.ev), length(quad.eu - quad.ev));
  }

  // A point drawn uniformly by area from (u1, u2) in [0, 1)^2, as sample_light_point draws the prim's.
  V3 point(double u1, double u2) const {
    if (!is_disk) return quad.corner + quad.eu * u1 + quad.ev * u2;
    return disk_point(disk, disk_radius(disk.r_in, disk.r_out, u1), kTwoPi * u2);
  }

  // The intervals [lo, hi] of the parameter s of the line x0 + s d (|d| = 1, in the light's plane) that lie
  // inside the light (a disk with a hole: up to two); returns how many.
  int clip(V3 x0, V3 d, double lo[2], double hi[2]) const {
    if (!is_disk) {
      double a = -INFINITY, b = INFINITY;
      for (const V3& dual : {quad.du, quad.dv}) {  // 0 <= (x - corner) . dual <= 1
        const double c0 = dot(x0 - quad.corner, dual), c1 = dot(d, dual);
        if (std::fabs(c1) < 1e-300) {
          if (!(c0 >= 0.0 && c0 <= 1.0)) return 0;
          continue;
        }
        const double s0 = -c0 / c1, s1 = (1.0 - c0) / c1;
        a = std::max(a, std::min(s0, s1));
        b = std::min(b, std::max(s0, s1));
      }
      if (!(a <= b)) return 0;
      lo[0] = a;
      hi[0] = b;
      return 1;
    }
    // |x0 + s d - c|^2 = r^2: s = -e +- sqrt(e^2 - f + r^2).
    const V3 o = x0 - disk.center;
    const double e = dot(o, d), f = dot(o, o);
    const double disc_out = e * e - f + disk.r_out * disk.r_out;
    if (!(disc_out > 0.0)) return 0;
    const double w_out = std::sqrt(disc_out), disc_in = e * e - f + disk.r_in * disk.r_in;
    if (!(disk.r_in > 0.0 && disc_in > 0.0)) {
      lo[0] = -e - w_out;
      hi[0] = -e + w_out;
      return 1;
    }
    const double w_in = std::sqrt(disc_in);
    lo[0] = -e - w_out;
    hi[0] = -e - w_in;
    lo[1] = -e + w_in;
    hi[1] = -e + w_out;
    return 2;
  }
};

// The proposal's margin round each light: the metric's own bound on how far its images of a light point lie from
// the proxy's (MetricBase::lens_proxy_margin; Kerr: twice its spin length a), or where the metric gives none, this
// fraction of the light's size (the square root of its area); at most kProposalMarginMax of that size.
inline constexpr double kProposalMargin = 0.05, kProposalMarginMax = 0.5;
// The margin's share of the proposal's draws. Fewer than by area (a third of a 30-unit lamp's grown by 3 units
// all round, most of them wasted: Kerr's ray from the vertex seldom lands on the light from there) and a wider
// margin: fig10d's relative MSE (direct light, 48 x 36 x 16) 0.0586 by area with a margin of a, 0.0534 with 2a
// and a share of 0.15-0.2, 0.0548 with a and 0.2, 0.0563 with 3a and 0.3 (benchmarks/README.md).
inline constexpr double kProposalMarginShare = 0.15;

// A light as the proposal draws its points B: on the light itself with probability 1 - q, in the margin round it
// (its grown shape less the light) with probability q, each uniformly by area; `density` is the draws' density
// per unit area at a point of the grown shape, a function of the point alone.
struct ProposalLight {
  PlanarLight light, grown;
  double q = 0.0;  // the margin's share of the draws (0 where there is no margin)
  double area_light = 0.0, area_margin = 0.0;
  double s0 = 0.0, s1 = 1.0, r0 = 0.0, r1 = 1.0;  // (a quad) the light's edges in the grown quad's coordinates

  ProposalLight() = default;
  // Light L grown by its margin (metric_margin: the metric's, negative where it gives none, 0 for none at all),
  // the margin drawn with probability q_margin.
  ProposalLight(const PlanarLight& L, double metric_margin, double q_margin = kProposalMarginShare) : light(L) {
    const double size = std::sqrt(L.area());
    const double margin = metric_margin >= 0.0 ? metric_margin : kProposalMargin * size;
    grown = L.grown(std::min(margin, kProposalMarginMax * size));
    area_light = L.area();
    area_margin = std::max(0.0, grown.area() - area_light);
    q = area_margin > 1e-12 * area_light ? q_margin : 0.0;
    if (!L.is_disk) {
      const Quad& g = grown.quad;
      s0 = dot(L.quad.corner - g.corner, g.du);
      s1 = dot(L.quad.corner + L.quad.eu - g.corner, g.du);
      r0 = dot(L.quad.corner - g.corner, g.dv);
      r1 = dot(L.quad.corner + L.quad.ev - g.corner, g.dv);
    }
  }

  bool on_light(V3 x) const { return light.contains(x); }

  // The density per unit area of the draws at point x of the grown shape.
  double density(V3 x) const { return on_light(x) ? (1.0 - q) / area_light : q / area_margin; }

  // The point drawn from (u1, u2) in [0, 1)^2.
  V3 point(double u1, double u2) const {
    if (!(u1 >= 1.0 - q)) return light.point(q > 0.0 ? u1 / (1.0 - q) : u1, u2);
    double t = (u1 - (1.0 - q)) / q;  // in [0, 1): which part of the margin, then where in it
    if (light.is_disk) {  // the band outside the light, or the one inside its hole
      const Disk &k = light.disk, &g = grown.disk;
      const double out = g.r_out * g.r_out - k.r_out * k.r_out, in = k.r_in * k.r_in - g.r_in * g.r_in;
      const bool outer = t * (out + in) < out;
      const double lo = outer ? k.r_out : g.r_in, hi = outer ? g.r_out : k.r_in;
      t = outer ? t * (out + in) / out : (t * (out + in) - out) / in;
      return disk_point(k, disk_radius(lo, hi, std::min(t, 1.0)), kTwoPi * u2);
    }
    // (a quad) four strips of the grown quad's unit square round the light's rectangle [s0, s1] x [r0, r1]
    const double a[4] = {r0, 1.0 - r1, s0 * (r1 - r0), (1.0 - s1) * (r1 - r0)};
    const double total = a[0] + a[1] + a[2] + a[3];
    double x = t * total, s, r;
    int i = 0;
    while (i < 3 && x >= a[i]) x -= a[i++];
    const double f = a[i] > 0.0 ? std::min(x / a[i], 1.0) : 0.0;
    if (i == 0) s = u2, r = f * r0;
    else if (i == 1) s = u2, r = r1 + f * (1.0 - r1);
    else if (i == 2) s = f * s0, r = r0 + u2 * (r1 - r0);
    else s = s1 + f * (1.0 - s1), r = r0 + u2 * (r1 - r0);
    return grown.quad.corner + grown.quad.eu * s + grown.quad.ev * r;
  }
};

// Whether light prim p's shape is one the proposal finds crossings with (quads and disks: planar).
inline bool proposal_light(const Scene& sc, int p) {
  const PrimKind k = sc.prims[p].kind;
  return k == PrimKind::kQuad || k == PrimKind::kDisk;
}

// Planar light prim p.
inline PlanarLight planar_light(const Scene& sc, int p) {
  PlanarLight L;
  const Prim& pr = sc.prims[p];
  L.is_disk = pr.kind == PrimKind::kDisk;
  if (L.is_disk)
    L.disk = sc.disks[pr.index];
  else
    L.quad = sc.quads[pr.index];
  return L;
}

namespace detail {

// The user-frame tangent t (perpendicular to the vertex's radial direction xa) that lens_image_rays maps to
// the local tangent t_local: the inverse of t -> normalize(to_local(t) projected off radial_local).
inline bool user_tangent(const LinearMap& to_local, V3 radial_local, V3 xa, V3 t_local, V3& t_user) {
  V3 p1, p2;
  basis_around(xa, p1, p2);
  auto off_radial = [&](V3 q) { return q - radial_local * dot(q, radial_local); };
  const V3 q1 = off_radial(to_local(p1)), q2 = off_radial(to_local(p2));
  const double g11 = dot(q1, q1), g12 = dot(q1, q2), g22 = dot(q2, q2);
  const double det = g11 * g22 - g12 * g12;
  if (!(det > 1e-24 * g11 * g22)) return false;
  const double r1 = dot(q1, t_local), r2 = dot(q2, t_local);
  t_user = normalize(p1 * ((g22 * r1 - g12 * r2) / det) + p2 * ((g11 * r2 - g12 * r1) / det));
  return finite(t_user);
}

}  // namespace detail

// Where the proxy orbit from vertex v along local direction w first crosses light prim p.
struct LightCrossing {
  bool ok = false;
  V3 pos;             // user frame
  double sweep = 0.0;  // azimuth swept from the vertex (order = floor(sweep / pi))
};

// The proxy's mass by the plane and sense of an orbit, in a metric that turns (Kerr). A proxy of one mass captures
// rays that Kerr's frame dragging lets pass round the hole on the side that turns with it, and bends too little
// the rays on the other side (in fig10d half of the BSDF samples that reached the lamp by a direction the proposal
// could not draw had a proxy orbit that fell into the hole). So each orbit gets a mass between the metric's and
// the Schwarzschild mass whose critical impact parameter is the metric's at the orbit's inclination
// (MetricBase::lens_proxy_mass; Kerr a = 0.9 M: 0.55 M turning with the hole, 0.93 M over the poles, 1.31 M
// against it), kProxyMassBlend of the way: the strong field wants all of it, the weak field none (its deflection is
// the mass's). Tabulated in the cosine c of the angle between the light's angular momentum and the spin. A
// function of the orbit's plane and sense alone: a map whose mass changes only from plane to plane keeps the
// Schwarzschild map's area Jacobian (moving the direction within the plane moves the point within it at that
// plane's mass; moving it across turns the plane, which only adds a component within the plane to the point's
// move), so the proposal's pdf stays exact.
inline constexpr double kProxyMassBlend = 0.5;

class ProxyMass {
 public:
  static constexpr int kTable = 129;
  ProxyMass() = default;
  // Mass M; spin: the metric's spin vector (zero: the proxy has mass M for every orbit); mass_of(c): the
  // critical-impact-parameter mass at cosine c (<= 0: none, M).
  template <class MassOf>
  ProxyMass(double M, V3 spin, const MassOf& mass_of) : M_(M) {
    const double s = length(spin);
    if (!(s > 0.0)) return;
    axis_ = spin / s;
    for (int i = 0; i < kTable; ++i) {
      const double m = mass_of(-1.0 + 2.0 * double(i) / double(kTable - 1));
      table_[i] = m > 0.0 && std::isfinite(m) ? M + kProxyMassBlend * (m - M) : M;
    }
    varies_ = true;
  }

  // The mass of the proxy orbit that a backward ray turning about unit normal n (user frame, by the right hand)
  // follows (the light itself turns the other way).
  double at(V3 n) const {
    if (!varies_) return M_;
    const double x = std::clamp(0.5 * (1.0 - dot(n, axis_)) * double(kTable - 1), 0.0, double(kTable - 1));
    const int i = std::min(int(x), kTable - 2);
    const double f = x - double(i);
    return table_[i] + f * (table_[i + 1] - table_[i]);
  }

 private:
  double M_ = 0.0;
  V3 axis_;
  bool varies_ = false;
  double table_[kTable] = {};
};

// The first crossing, within swept azimuth orders * pi, of the Schwarzschild orbit that leaves the vertex at
// user-frame pos (its local frame: to_local, radial_local the outward radial direction) along local direction w
// with planar light L; the orbit's mass mass_of(n) where n is the unit normal about which it turns (user frame).
template <class MassOf>
inline LightCrossing first_light_crossing(const MassOf& mass_of, V3 pos, V3 radial_local, const LinearMap& to_local,
                                          V3 w, const PlanarLight& L, int orders) {
  LightCrossing none;
  const double RA = length(pos);
  if (!(RA > 0.0)) return none;
  const V3 xa = pos / RA;
  const double cpsi = dot(w, radial_local);
  const V3 tang = w - radial_local * cpsi;
  const double spsi = length(tang);
  if (!(spsi > 1e-9)) return none;
  V3 t;
  if (!detail::user_tangent(to_local, radial_local, xa, tang / spsi, t)) return none;
  t = normalize(t - xa * dot(t, xa));
  const double M = mass_of(cross(xa, t));
  const double uA = 1.0 / RA, lapse2 = 1.0 - 2.0 * M * uA;
  if (!(lapse2 > 0.0)) return none;
  const PlanarOrbit orbit(M, spsi / (uA * std::sqrt(lapse2)), uA, cpsi < 0.0);
  if (!orbit.valid()) return none;
  // Where the orbit ends (escapes or reaches the horizon) and the largest u it reaches before.
  const double end = orbit.falls_in() ? orbit.phi_of(0.5 / M, false) : orbit.phi_of(0.0, true);
  const double phi_max = std::min(double(orders) * M_PI, std::isfinite(end) ? end : 0.0);
  if (!(phi_max > 0.0)) return none;
  const double u_top = orbit.falls_in() ? 0.5 / M : orbit.u_peak(uA);

  // The light's plane within the orbit's plane (spanned by xa and t): the line alpha X + beta Y = delta.
  const V3 c = L.origin(), nl = L.normal();
  const double alpha = dot(xa, nl), beta = dot(t, nl), delta = dot(c, nl);
  const double ab = std::hypot(alpha, beta);
  if (!(ab > 1e-12)) return none;  // the planes are parallel
  const V3 x0 = (xa * alpha + t * beta) * (delta / (ab * ab)), d = (t * alpha - xa * beta) / ab;
  double slo[2], shi[2];
  const int nseg = L.clip(x0, d, slo, shi);
  const double G = ab + std::fabs(delta) * u_top * (1.0 + 3.0 * M * u_top);
  auto g = [&](double phi, double* dg) {
    double du;
    const double u = orbit.u(phi, dg ? &du : nullptr);
    const double cp = std::cos(phi), sp = std::sin(phi);
    if (dg) *dg = -alpha * sp + beta * cp - delta * du;
    return alpha * cp + beta * sp - delta * u;
  };
  // The first root of g in [lo, hi] (g values glo, ghi), or NaN.
  auto first_root = [&](auto&& self, double lo, double hi, double glo, double ghi, int depth) -> double {
    if (glo == 0.0) return lo;
    const double h = hi - lo;
    const bool change = (glo < 0.0) != (ghi < 0.0) || ghi == 0.0;
    if (std::fabs(ghi - glo) > G * h * h) {  // g' keeps its sign: at most one root
      if (!change) return NAN;
      double a = lo, b = hi, ga = glo, x = lo - glo * h / (ghi - glo);
      for (int it = 0; it < 60; ++it) {
        double dgx;
        const double gx = g(x, &dgx);
        if (gx == 0.0) return x;
        if ((gx < 0.0) == (ga < 0.0)) {
          a = x;
          ga = gx;
        } else {
          b = x;
        }
        double next = x - gx / dgx;
        if (!(next > a && next < b)) next = 0.5 * (a + b);
        if (std::fabs(next - x) <= 1e-14 * (1.0 + std::fabs(x)) || b - a <= 1e-14 * (1.0 + std::fabs(x)))
          return next;
        x = next;
      }
      return x;
    }
    if (!change && std::min(std::fabs(glo), std::fabs(ghi)) > 0.125 * G * h * h) return NAN;
    if (depth >= 48) return change ? 0.5 * (lo + hi) : NAN;  // a graze, to rounding
    const double mid = 0.5 * (lo + hi), gm = g(mid, nullptr);
    const double left = self(self, lo, mid, glo, gm, depth + 1);
    return std::isnan(left) ? self(self, mid, hi, gm, ghi, depth + 1) : left;
  };

  double best = INFINITY;
  const bool through_centre = std::fabs(delta) <= 1e-12 * (1.0 + length(c));
  for (int k = 0; k < nseg; ++k) {
    if (through_centre) {
      // The line passes through the centre: the orbit meets it where its polar angle points along it.
      for (double side : {1.0, -1.0}) {
        const double phi0 = std::atan2(side * dot(d, t), side * dot(d, xa));
        for (int turn = 0; turn < 3; ++turn) {
          const double phi = (phi0 < 0.0 ? phi0 + kTwoPi : phi0) + kTwoPi * turn;
          if (!(phi > 0.0 && phi < phi_max && phi < best)) continue;
          const double u = orbit.u(phi);
          if (!(u > 0.0)) continue;
          const double s = side / u;
          if (s >= slo[k] && s <= shi[k]) best = phi;
        }
      }
      continue;
    }
    // The segment's polar angles: an arc shorter than pi (the line misses the centre).
    const V3 pa = x0 + d * slo[k], pb = x0 + d * shi[k];
    double a0 = std::atan2(dot(pa, t), dot(pa, xa));
    double span = std::atan2(dot(pb, t), dot(pb, xa)) - a0;
    span = std::remainder(span, kTwoPi);
    if (span < 0.0) {
      a0 += span;
      span = -span;
    }
    if (a0 < 0.0) a0 += kTwoPi;
    for (int turn = -1; turn < 3; ++turn) {
      const double lo = std::max(1e-12, a0 + kTwoPi * turn), hi = std::min(phi_max, a0 + span + kTwoPi * turn);
      if (!(lo < hi) || !(lo < best)) continue;
      const double r = first_root(first_root, lo, hi, g(lo, nullptr), g(hi, nullptr), 0);
      if (r < best) best = r;
    }
  }
  if (!std::isfinite(best)) return none;
  const double u = orbit.u(best);
  if (!(u > 0.0)) return none;
  LightCrossing out;
  out.ok = true;
  out.sweep = best;
  out.pos = (xa * std::cos(best) + t * std::sin(best)) / u;
  return out;
}

// The same for a proxy of one mass M.
inline LightCrossing first_light_crossing(double M, V3 pos, V3 radial_local, const LinearMap& to_local, V3 w,
                                          const PlanarLight& L, int orders) {
  return first_light_crossing([M](V3) { return M; }, pos, radial_local, to_local, w, L, orders);
}

}  // namespace wv
