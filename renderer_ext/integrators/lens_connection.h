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
// for efficiency, and it is exact to the integrator's tolerance. In Kerr the same draw, in the Schwarzschild
// map of the same mass, is a proposal whose pdf is evaluated where a direction's proxy orbit first crosses
// the light (lens_proposal.h).
//
// The area Jacobian of an image whose ray leaves A at angle psi from the outward radial direction and
// sweeps Phi to reach B (radius R_B) at arrival direction t (user frame):
//
//   |dA_B / dOmega_A| = R_B^2 |sin Phi| |dPhi/dpsi| / sin(psi) * |t . r_B| / |t . n_B|.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/trig.h"
#include "core/vec3.h"
#include "integrators/lens_proposal.h"
#include "integrators/segment.h"
#include "scene/light.h"
#include "scene/material.h"
#include "scene/scene.h"
#include "spacetime/lens_map.h"

namespace wv {

// 1 - cos of 1e-3 rad: a traced ray is the image it follows to ~1e-6 rad, and distinct images lie far apart.
inline constexpr double kLensMatchCos = 5e-7;

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
  double jacobian[kMax];  // |dA_B / dOmega_A| (0 where the weight is 0)
  double total = 0.0;
  double area = 0.0;   // sampled: the light's (a sphere's: its half facing the vertex)
};

// The lens connection's view of a surface hit.
inline LensVertex lens_vertex(const SegmentEnd& e) {
  LensVertex v;
  v.pos = e.pos;
  v.sheet = e.sheet;
  v.to_local = e.to_local;
  v.radial_local = normalize(e.to_local(normalize(e.pos)));
  v.normal_local = e.normal_local;
  return v;
}

// A light point as the lens connection sees it.
struct LensLight {
  V3 pos, normal;       // user frame
  double area = 0.0;    // sampled: the light's (a sphere's: its half facing the vertex)
  int sheet = 1;
  bool two_sided = false;
};

// The rays of the images of order < orders of light point b seen from vertex v: each root of the lens
// map with its direction w at v (local), its sense of rotation about the centre t_user (user frame, and
// t_local), and at B the in-plane direction phi_hat and the arrival direction t_arr (user frame).
struct LensImageRay {
  LensRay r;
  V3 w, t_user, t_local, phi_hat, t_arr;
};
struct LensImageRays {
  int n = 0;
  double RB = 0.0;
  V3 xa, xb;  // unit radial directions of A and B
  LensImageRay ray[LensImages::kMax];
};

inline LensImageRays lens_image_rays(const SphericalLens& lens, const LensVertex& v, const LensLight& b, int orders) {
  LensImageRays out;
  const double RA = length(v.pos), RB = length(b.pos);
  if (!(RA > 0.0 && RB > 0.0)) return out;
  out.RB = RB;
  const V3 xa = v.pos / RA, xb = b.pos / RB;
  out.xa = xa;
  out.xb = xb;
  const V3 side = xb - xa * dot(xb, xa);  // towards B, perpendicular to A's radial direction
  const double sin_g = length(side);
  if (!(sin_g > 1e-9)) return out;
  const double gamma = std::atan2(sin_g, dot(xa, xb));
  const V3 toward = side / sin_g;
  const LensMap map(lens, 1.0 / RA, 1.0 / RB, b.sheet == v.sheet);
  if (!map.valid()) return out;
  // Orders in turn, each started from the last one's root moved on by the difference in Phi: far along a
  // branch (towards the photon sphere or the throat) Phi grows about as fast as z, which saves 1-4 of the
  // 4-8 evaluations a plain Newton start from the last root takes (Schwarzschild, Ellis).
  double z = map.direct_guess(gamma), last_target = gamma;
  for (int m = 0; m < std::min(orders, LensImages::kMax); ++m) {
    const bool long_way = m % 2 == 1;
    const double target = long_way ? kTwoPi * double((m + 1) / 2) - gamma : kTwoPi * double(m / 2) + gamma;
    if (m > 0) z += target - last_target;
    last_target = target;
    LensImageRay& ir = out.ray[out.n];
    ir.r = map.solve(target, z, &z);
    if (!ir.r.ok) break;
    ir.t_user = long_way ? -toward : toward;
    V3 t_local = v.to_local(ir.t_user);
    ir.t_local = normalize(t_local - v.radial_local * dot(t_local, v.radial_local));
    double spsi, cpsi, sp, cp;
    sin_cos(ir.r.psi, spsi, cpsi);
    sin_cos(ir.r.phi, sp, cp);
    ir.w = v.radial_local * cpsi + ir.t_local * spsi;
    ir.phi_hat = xa * (-sp) + ir.t_user * cp;
    ir.t_arr = normalize(xb * ir.r.dr_dphi + ir.phi_hat * RB);
    ++out.n;
  }
  return out;
}

// |dA_B / dOmega_A| of image ray ir (user frame): the area it sweeps at B per solid angle at A, on a plane through
// B whose normal has |cosine| cos_n with the arrival direction (1: the plane across the ray).
inline double lens_area_jacobian(const LensImageRays& rays, const LensImageRay& ir, double cos_n) {
  const double cos_r = std::fabs(dot(ir.t_arr, rays.xb));
  return rays.RB * rays.RB * std::fabs(std::sin(ir.r.phi)) * std::fabs(ir.r.dphi_dpsi) * cos_r /
         (std::sin(ir.r.psi) * cos_n);
}

// The images of order < orders of light point b seen from vertex v, with their weights.
inline LensImages lens_images(const SphericalLens& lens, const LensVertex& v, const LensLight& b, int orders) {
  LensImages im;
  im.area = b.area;
  const LensImageRays rays = lens_image_rays(lens, v, b, orders);
  for (int k = 0; k < rays.n; ++k) {
    const LensImageRay& ir = rays.ray[k];
    // The area Jacobian from the sweep's derivative and the arrival direction.
    const double cos_n = dot(ir.t_arr, b.normal);
    double weight = 0.0;
    const double cos_a = dot(ir.w, v.normal_local);
    if (cos_a > 0.0 && (b.two_sided || cos_n < 0.0) && std::isfinite(ir.r.dphi_dpsi)) {
      const double jac = lens_area_jacobian(rays, ir, std::fabs(cos_n));
      if (jac > 0.0 && std::isfinite(jac)) weight = cos_a / jac;
    }
    im.w[im.n] = ir.w;
    im.jacobian[im.n] = weight > 0.0 ? cos_a / weight : 0.0;
    im.weight[im.n] = weight;
    im.total += weight;
    ++im.n;
  }
  return im;
}

// An image of light point b seen from v with the lens map's local linearisation: its direction w (local),
// an orthonormal tangent basis e1, e2 (local) and how a displacement of w along them moves the point the
// ray reaches on the light's plane (user frame): the columns d_e1, d_e2 of the 3 x 2 Jacobian.
struct LensImageFrame {
  V3 w, e1, e2, d_e1, d_e2;
};

// The image frames of order < orders of point b (normal b.normal) from v; returns how many.
inline int lens_image_frames(const SphericalLens& lens, const LensVertex& v, const LensLight& b, int orders,
                             LensImageFrame* out) {
  const LensImageRays rays = lens_image_rays(lens, v, b, orders);
  int n = 0;
  for (int k = 0; k < rays.n; ++k) {
    const LensImageRay& ir = rays.ray[k];
    if (!std::isfinite(ir.r.dphi_dpsi)) break;
    const double sp = std::sin(ir.r.phi), spsi = std::sin(ir.r.psi);
    const double tn = dot(ir.t_arr, b.normal);
    if (!(std::fabs(tn) > 1e-9) || !(spsi > 1e-12)) continue;
    auto onto_plane = [&](V3 d) { return d - ir.t_arr * (dot(d, b.normal) / tn); };
    LensImageFrame& f = out[n++];
    f.w = ir.w;
    f.e1 = v.radial_local * (-spsi) + ir.t_local * std::cos(ir.r.psi);  // towards larger psi
    f.e2 = normalize(cross(v.radial_local, ir.t_local));                 // about the radial axis
    f.d_e1 = onto_plane(ir.phi_hat * (rays.RB * ir.r.dphi_dpsi));
    f.d_e2 = onto_plane(normalize(cross(rays.xa, ir.t_user)) * (rays.RB * sp / spsi));
  }
  return n;
}

// Solid-angle pdf with which the light strategy at v, choosing this light with probability p_light, draws
// local direction w whose geodesic first reaches the light at b (0 unless w is one of b's images).
inline double lens_pdf(const SphericalLens& lens, const LensVertex& v, V3 w, const LensLight& b, int orders,
                       double p_light) {
  const LensImages im = lens_images(lens, v, b, orders);
  if (!(im.total > 0.0)) return 0.0;
  for (int i = 0; i < im.n; ++i) {
    if (im.weight[i] > 0.0 && dot(im.w[i], w) > 1.0 - kLensMatchCos)
      return p_light * dot(w, v.normal_local) / (im.area * im.total);
  }
  return 0.0;
}

template <class M>
class LensConnection {
 public:
  // With `proposal`, a metric with a lens proxy (Kerr) uses the proxy's connection as a proposal
  // (lens_proposal.h) where every light is planar.
  LensConnection(const M& m, const Scene& sc, int orders, bool proposal)
      : sc_(sc), orders_(std::clamp(orders, 1, LensImages::kMax)) {
    if constexpr (M::kStaticSpherical) {
      lens_ = m.spherical_lens();
    } else if constexpr (M::kLensProxy) {
      lens_ = m.lens_proxy();
      proposal_mass_ = lens_.cubic_mass();
      proposal_ = proposal && proposal_mass_ > 0.0 && !sc.lights.empty() &&
                  std::all_of(sc.lights.begin(), sc.lights.end(), [&](int p) { return proposal_light(sc, p); });
      if (proposal_)
        for (int p : sc.lights) planar_.push_back(planar_light(sc, p));
    }
  }

  const SphericalLens& lens() const { return lens_; }
  int orders() const { return orders_; }

  // Whether the connection applies at vertex e (else the aimed proxies do): the metric is static and
  // spherical and e lies outside the innermost sphere its lens map covers (by 5 %); or the proxy's
  // connection is a proposal here and e lies outside 1.3 times the proxy's photon sphere (where Kerr's
  // images still lie near the proxy's). A choice made from the vertex alone, so both strategies agree on it.
  bool applies(const SegmentEnd& e) const {
    if constexpr (M::kStaticSpherical) {
      return lens_.u_inner > 0.0 && length(e.pos) * lens_.u_inner > 1.05;
    } else {
      return proposal_ && length(e.pos) * lens_.u_inner > 1.3;
    }
  }


  // A direction from v towards light number li (of the scene's light list), chosen with probability 1 / per,
  // and its pdf, with the point aimed at; u1, u2 pick the point, u3 the image.
  bool sample(const LensVertex& v, int li, double u1, double u2, double u3, V3& w, double& pdf, V3& target,
              double per) const {
    const int p = sc_.lights[li];
    LightPoint lp;
    if (!sample_light_point(sc_, p, v.pos, u1, u2, lp)) return false;
    const LensImages im = lens_images(lens_, v, light(p, lp), orders_);
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
    pdf = dot(w, v.normal_local) / (im.area * im.total * per);
    target = lp.pos;
    if (proposal_) {  // it counts only if its proxy orbit crosses the light first at B
      const LightCrossing x = crossing(v, w, li);
      if (!x.ok || length(x.pos - lp.pos) > 1e-6 * (1.0 + length(lp.pos))) return false;
    }
    return pdf > 0.0 && std::isfinite(pdf);
  }

  // Whether a light sample aimed at `target` on light prim p counts: its geodesic first hit that point (as a
  // proposal: that light, anywhere).
  bool light_sample_hits(const SegmentEnd& le, int p, V3 target) const {
    if (proposal_) return le.status == kHit && le.prim == p;
    return le.status == kHit && le.prim == p && length(le.pos - target) <= 1e-4 * (1.0 + length(target));
  }

  // Solid-angle pdf with which the light strategy at v draws local direction w whose geodesic first hits
  // prim p at user-frame point x (0 if p is not a light or w not one of x's images of order < N; as a
  // proposal, whatever x: the pdf is that of the point where w's proxy orbit first crosses the light); the
  // lights chosen with probabilities sel (null: evenly).
  double pdf(const LensVertex& v, V3 w, int p, V3 x, const double* sel) const {
    const auto it = std::find(sc_.lights.begin(), sc_.lights.end(), p);
    if (p < 0 || it == sc_.lights.end()) return 0.0;
    if (proposal_) {
      const LightCrossing c = crossing(v, w, int(it - sc_.lights.begin()));
      if (!c.ok) return 0.0;
      x = c.pos;
    }
    LightPoint lp;
    if (!light_point_at(sc_, p, v.pos, x, lp)) return 0.0;
    const double p_light = sel ? sel[it - sc_.lights.begin()] : 1.0 / double(sc_.light_count());
    return lens_pdf(lens_, v, w, light(p, lp), orders_, p_light);
  }

 private:
  // As a proposal: where the proxy orbit from v along w first crosses light number li.
  LightCrossing crossing(const LensVertex& v, V3 w, int li) const {
    return first_light_crossing(proposal_mass_, v.pos, v.radial_local, v.to_local, w, planar_[size_t(li)], orders_);
  }

  LensLight light(int p, const LightPoint& lp) const {
    LensLight b;
    b.pos = lp.pos;
    b.normal = lp.normal;
    b.area = lp.area;
    b.sheet = sc_.prims[p].sheet;
    b.two_sided = sc_.materials[sc_.prims[p].material].two_sided;
    return b;
  }

  const Scene& sc_;
  SphericalLens lens_;
  int orders_;
  bool proposal_ = false;
  double proposal_mass_ = 0.0;
  std::vector<PlanarLight> planar_;  // as a proposal: each light's shape
};

}  // namespace wv
