// The lens-aware light connection of static spherical spacetimes (Schwarzschild, Reissner-Nordstrom,
// Ellis): at a diffuse vertex A a point B is drawn on a light by area and one of the light rays from A to
// B is chosen among its images of order 0 .. N-1 (spacetime/lens_map.h: order 0 the direct image, 1 the
// one round the far side, 2 the first winding, ...), each with probability proportional to what it is
// worth to a diffuse surface, w_m = cos(theta_m) |dOmega_A / dA_B|_m (one-sided lights: 0 from behind).
// The solid-angle pdf of the chosen direction is then
//
//   p(omega_m) = P(light) (1 / area) (w_m / W) |dA_B / dOmega_A|_m = P(light) cos(theta_m) / (area W),
//
// W = sum of the w. It depends on B alone, so a BSDF-sampled ray that first hits a light at B' has the
// light strategy's pdf as soon as the images of B' are known: p is that formula if the ray is one of B''s
// images of order < N, else 0 (the light strategy never draws it). A light sample counts only if its
// geodesic's first hit is the point it aimed at (light_sample_hits), so both strategies use the pdf of the
// first light crossing and multiple importance sampling stays unbiased: the lens map only has to be right
// for efficiency, and it is exact to the integrator's tolerance.
//
// The area Jacobian of an image whose ray leaves A at angle psi from the outward radial direction and
// sweeps Phi to reach B (radius R_B) at arrival direction t (user frame):
//
//   |dA_B / dOmega_A| = R_B^2 |sin Phi| |dPhi/dpsi| / sin(psi) * |t . r_B| / |t . n_B|.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/vec3.h"
#include "integrators/segment.h"
#include "scene/light.h"
#include "scene/material.h"
#include "scene/scene.h"
#include "spacetime/lens_map.h"

namespace wv {

// What the lens connection needs of a diffuse vertex.
struct LensVertex {
  V3 pos;           // user frame
  int sheet = 1;
  V3 radial_local;  // the outward radial direction in the local frame
  V3 normal_local;
  LinearMap to_local;
};

// The images of one light point B seen from a vertex.
struct LensImages {
  static constexpr int kMax = 4;
  int n = 0;
  V3 w[kMax];          // local direction at the vertex
  double weight[kMax];  // cos(theta) |dOmega / dA|
  double total = 0.0;
  double area = 0.0;   // of the light
};

template <class M>
class LensConnection {
 public:
  LensConnection(const M& m, const Scene& sc, int orders) : sc_(sc), orders_(std::clamp(orders, 1, LensImages::kMax)) {
    if constexpr (M::kStaticSpherical) lens_ = m.spherical_lens();
  }

  // Whether the connection applies at vertex e (else the aimed proxies do): the metric is static and
  // spherical and e lies outside the innermost sphere its lens map covers. A choice made from the vertex
  // alone, so both strategies agree on it.
  bool applies(const SegmentEnd& e) const {
    if constexpr (!M::kStaticSpherical) {
      (void)e;
      return false;
    } else {
      const double r = length(e.pos);
      return lens_.u_inner > 0.0 && r * lens_.u_inner > 1.05;
    }
  }

  LensVertex vertex(const SegmentEnd& e) const {
    LensVertex v;
    v.pos = e.pos;
    v.sheet = e.sheet;
    v.to_local = e.to_local;
    v.radial_local = normalize(e.to_local(normalize(e.pos)));
    v.normal_local = e.normal_local;
    return v;
  }

  // The images of order < N of point lp on light prim p as seen from v.
  LensImages images(const LensVertex& v, int p, const LightPoint& lp) const {
    LensImages im;
    im.area = lp.area;
    const double RA = length(v.pos), RB = length(lp.pos);
    if (!(RA > 0.0 && RB > 0.0)) return im;
    const V3 xa = v.pos / RA, xb = lp.pos / RB;
    const V3 side = xb - xa * dot(xb, xa);  // towards B, perpendicular to A's radial direction
    const double sin_g = length(side);
    if (!(sin_g > 1e-9)) return im;
    const double gamma = std::atan2(sin_g, dot(xa, xb));
    const V3 toward = side / sin_g;
    const LensMap map(lens_, 1.0 / RA, 1.0 / RB, sc_.prims[p].sheet == v.sheet);
    if (!map.valid()) return im;
    const Material& mat = sc_.materials[sc_.prims[p].material];
    // Orders in turn, each started from the last one's root (Phi grows with z).
    double z = map.flat_guess(gamma);
    for (int m = 0; m < orders_; ++m) {
      const bool long_way = m % 2 == 1;
      const double target = long_way ? kTwoPi * double((m + 1) / 2) - gamma : kTwoPi * double(m / 2) + gamma;
      const LensRay r = map.solve(target, z, &z);
      if (!r.ok) break;
      const V3 t_user = long_way ? -toward : toward;  // the ray's sense of rotation about the centre
      V3 t_local = v.to_local(t_user);
      t_local = normalize(t_local - v.radial_local * dot(t_local, v.radial_local));
      const V3 w = v.radial_local * std::cos(r.psi) + t_local * std::sin(r.psi);
      // Arrival direction at B and the area Jacobian.
      const double sp = std::sin(r.phi), cp = std::cos(r.phi);
      const V3 phi_hat = xa * (-sp) + t_user * cp;
      const V3 t_arr = normalize(xb * r.dr_dphi + phi_hat * RB);
      const double cos_r = std::fabs(dot(t_arr, xb)), cos_n = dot(t_arr, lp.normal);
      double weight = 0.0;
      const double cos_a = dot(w, v.normal_local);
      if (cos_a > 0.0 && (mat.two_sided || cos_n < 0.0) && std::isfinite(r.dphi_dpsi)) {
        const double jac = RB * RB * std::fabs(sp) * std::fabs(r.dphi_dpsi) * cos_r /
                           (std::sin(r.psi) * std::fabs(cos_n));
        if (jac > 0.0 && std::isfinite(jac)) weight = cos_a / jac;
      }
      im.w[im.n] = w;
      im.weight[im.n] = weight;
      im.total += weight;
      ++im.n;
    }
    return im;
  }

  // A direction from v towards light number li (of the scene's light list) and its pdf, with the point
  // aimed at.
  bool sample(const LensVertex& v, int li, double u1, double u2, double u3, V3& w, double& pdf, V3& target) const {
    const int p = sc_.lights[li];
    LightPoint lp;
    if (!sample_light_point(sc_, p, u1, u2, lp)) return false;
    const LensImages im = images(v, p, lp);
    if (!(im.total > 0.0)) return false;
    double acc = 0.0;
    int k = im.n - 1;
    for (int i = 0; i < im.n; ++i) {
      acc += im.weight[i];
      if (u3 * im.total < acc) {
        k = i;
        break;
      }
    }
    if (!(im.weight[k] > 0.0)) return false;
    w = im.w[k];
    pdf = dot(w, v.normal_local) / (im.area * im.total * double(sc_.lights.size()));
    target = lp.pos;
    return pdf > 0.0 && std::isfinite(pdf);
  }

  // Whether a light sample aimed at `target` on light prim p first hit that point.
  static bool light_sample_hits(const SegmentEnd& le, int p, V3 target) {
    return le.status == kHit && le.prim == p && length(le.pos - target) <= 1e-4 * (1.0 + length(target));
  }

  // Solid-angle pdf with which the light strategy at v draws local direction w whose geodesic first hits
  // light prim p at user-frame point x (0 unless w is one of x's images of order < N).
  double pdf(const LensVertex& v, V3 w, int p, V3 x) const {
    LightPoint lp;
    if (!light_point_at(sc_, p, x, lp)) return 0.0;
    const LensImages im = images(v, p, lp);
    if (!(im.total > 0.0)) return 0.0;
    for (int i = 0; i < im.n; ++i) {
      if (im.weight[i] > 0.0 && dot(im.w[i], w) > 1.0 - kMatchCos)
        return dot(w, v.normal_local) / (im.area * im.total * double(sc_.lights.size()));
    }
    return 0.0;
  }

  bool is_light(int prim) const {
    if (prim < 0) return false;
    for (int l : sc_.lights)
      if (l == prim) return true;
    return false;
  }

 private:
  static constexpr double kMatchCos = 5e-7;  // 1 - cos of 1e-3 rad: a traced ray is its image to ~1e-6

  const Scene& sc_;
  SphericalLens lens_;
  int orders_;
};

}  // namespace wv
