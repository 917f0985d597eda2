// The lens-aware light connection of static spherical spacetimes (Schwarzschild, Reissner-Nordstrom,
// Ellis): at a diffuse vertex A a point B is drawn on a light by area and one of the light rays from A to
// B is chosen among its images of order 0 .. N-1 (spacetime/lens_map.h: order 0 the direct image, 1 the
// one round the far side, 2 the first winding, ...), each with probability proportional to what it is
// worth to a diffuse surface, w_m = cos(theta_m) |dOmega_A / dA_B|_m (one-sided lights: 0 from behind;
// order 0's exact, the later orders' estimated without solving them, LensImagePick). The solid-angle pdf of
// the chosen direction is then
//
//   p(omega_m) = P(light) (1 / area) (w_m / W) |dA_B / dOmega_A|_m   (= P(light) cos(theta_m) / (area W)
//                                                                      where w_m is exact),
//
// W = sum of the w, with the image's own exact Jacobian. It depends on B alone, so a BSDF-sampled ray that
// first hits a light at B' has the light strategy's pdf as soon as B''s weights and the image it is are known:
// p is that formula if the ray is one of B''s images of order < N, else 0 (the light strategy never draws
// it). A light sample counts only if its geodesic's first hit is the point it aimed at (light_sample_hits),
// so both strategies use the pdf of the first light crossing and multiple importance sampling stays
// unbiased: the lens map only has to be right for efficiency, and it is exact to the integrator's tolerance. In
// Kerr the same draw, in Schwarzschild maps of about the same mass (one for each orbit plane and sense), is a
// proposal whose pdf is evaluated where a direction's proxy orbit first crosses the light (lens_proposal.h).
//
// The area Jacobian of an image whose ray leaves A at angle psi from the outward radial direction and
// sweeps Phi to reach B (radius R_B) at arrival direction t (user frame):
//
//   |dA_B / dOmega_A| = R_B^2 |sin Phi| |dPhi/dpsi| / sin(psi) * |t . r_B| / |t . n_B|.
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "core/trig.h"
#include "core/vec3.h"
#include "integrators/lens_focus.h"
#include "integrators/lens_proposal.h"
#include "integrators/segment.h"
#include "scene/light.h"
#include "scene/material.h"
#include "scene/scene.h"
#include "spacetime/lens_map.h"

namespace wv {

// 1 - cos of 1e-3 rad: a traced ray is the image it follows to ~1e-6 rad, and distinct images lie far apart.
inline constexpr double kLensMatchCos = 5e-7;

// Whether a ray aimed through the lens map at light point `target` (user frame) first hit x there: a traced ray
// lands on its aim to the integrator's tolerance; a ray that hits the light elsewhere first (the near side of a
// sphere in front of the point it aimed at) is another point's sample, whose density is not this one's.
inline bool hit_aim(V3 x, V3 target) { return length(x - target) <= 1e-4 * (1.0 + length(target)); }

// What the lens connection needs of a diffuse vertex.
struct LensVertex {
  V3 pos;           // user frame
  int sheet = 1;
  V3 radial_local;  // the outward radial direction in the local frame
  V3 normal_local;  // the surface's unit normal in the local frame, on the side the path arrived from
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
  // the normal on the side the path arrives from: a diffuse surface reflects on both sides (bsdf_eval), so a light
  // seen from the back of its geometric normal is drawn as from the front
  v.normal_local = e.normal_local * arrival_side(e);
  return v;
}

// A light point as the lens connection sees it.
struct LensLight {
  V3 pos, normal;       // user frame
  double area = 0.0;    // sampled: the light's (a sphere's: its half facing the vertex; the Kerr proposal's: 1 / the
                        // density of its draws at the point, lens_proposal.h)
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

// What every image of light point b seen from vertex v shares: the plane of A, B and the centre (A's and B's
// unit radial directions, the angle gamma = AOB between them and the tangent at A towards B) and the lens map
// between their radii. ok() false where there is no such plane or map.
class LensPair {
 public:
  LensPair(const SphericalLens& lens, const LensVertex& v, const LensLight& b)
      : RA_(length(v.pos)), RB_(length(b.pos)), map_(lens, 1.0 / RA_, 1.0 / RB_, b.sheet == v.sheet) {
    if (!(RA_ > 0.0 && RB_ > 0.0)) return;
    xa_ = v.pos / RA_;
    xb_ = b.pos / RB_;
    const V3 side = xb_ - xa_ * dot(xb_, xa_);  // towards B, perpendicular to A's radial direction
    const double sin_g = length(side);
    if (!(sin_g > 1e-9)) return;
    gamma_ = std::atan2(sin_g, dot(xa_, xb_));
    toward_ = side / sin_g;
    ok_ = map_.valid();
  }

  bool ok() const { return ok_; }
  const LensMap& map() const { return map_; }
  double gamma() const { return gamma_; }

  // The azimuth the image of order m sweeps: gamma + 2 pi (m / 2) the short way (m even), 2 pi ((m + 1) / 2) -
  // gamma the long way (m odd).
  double target(int m) const {
    return m % 2 == 1 ? kTwoPi * double((m + 1) / 2) - gamma_ : kTwoPi * double(m / 2) + gamma_;
  }

  // The images' shared frame in rays (B's radius, A's and B's radial directions).
  void frame(LensImageRays& rays) const {
    rays.RB = RB_;
    rays.xa = xa_;
    rays.xb = xb_;
  }

  // Image ray ir of order m from the lens map's ray r: its direction at v, its sense of rotation, and at B
  // its in-plane direction and arrival direction.
  void fill(const LensVertex& v, int m, const LensRay& r, LensImageRay& ir) const {
    ir.r = r;
    ir.t_user = m % 2 == 1 ? -toward_ : toward_;
    V3 t_local = v.to_local(ir.t_user);
    ir.t_local = normalize(t_local - v.radial_local * dot(t_local, v.radial_local));
    double spsi, cpsi, sp, cp;
    sin_cos(r.psi, spsi, cpsi);
    sin_cos(r.phi, sp, cp);
    ir.w = v.radial_local * cpsi + ir.t_local * spsi;
    ir.phi_hat = xa_ * (-sp) + ir.t_user * cp;
    ir.t_arr = normalize(xb_ * r.dr_dphi + ir.phi_hat * RB_);
  }

 private:
  double RA_, RB_;
  LensMap map_;
  bool ok_ = false;
  V3 xa_, xb_, toward_;
  double gamma_ = 0.0;
};

inline LensImageRays lens_image_rays(const SphericalLens& lens, const LensVertex& v, const LensLight& b, int orders) {
  LensImageRays out;
  const LensPair pair(lens, v, b);
  if (!pair.ok()) return out;
  pair.frame(out);
  const LensMap& map = pair.map();
  // Orders in turn, each started from the last one's root moved on by the difference in Phi: far along a
  // branch (towards the photon sphere or the throat) Phi grows about as fast as z, which saves 1-4 of the
  // 4-8 evaluations a plain Newton start from the last root takes (Schwarzschild, Ellis).
  double z = map.direct_guess(pair.gamma()), last_target = pair.gamma();
  for (int m = 0; m < std::min(orders, LensImages::kMax); ++m) {
    const double target = pair.target(m);
    if (m > 0) z += target - last_target;
    last_target = target;
    const LensRay r = map.solve(target, z, &z);
    if (!r.ok) break;
    pair.fill(v, m, r, out.ray[out.n]);
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

// What image ray ir of b is worth to a diffuse surface at v: cos(theta) |dOmega_A / dA_B| (0 from behind the
// surface or a one-sided light).
inline double lens_image_weight(const LensImageRays& rays, const LensImageRay& ir, const LensVertex& v,
                                const LensLight& b) {
  const double cos_n = dot(ir.t_arr, b.normal);
  const double cos_a = dot(ir.w, v.normal_local);
  if (cos_a > 0.0 && (b.two_sided || cos_n < 0.0) && std::isfinite(ir.r.dphi_dpsi)) {
    const double jac = lens_area_jacobian(rays, ir, std::fabs(cos_n));
    if (jac > 0.0 && std::isfinite(jac)) return cos_a / jac;
  }
  return 0.0;
}

// The images of order < orders of light point b seen from v, with their weights.
inline LensImages lens_images(const SphericalLens& lens, const LensVertex& v, const LensLight& b, int orders) {
  LensImages im;
  im.area = b.area;
  const LensImageRays rays = lens_image_rays(lens, v, b, orders);
  for (int k = 0; k < rays.n; ++k) {
    const LensImageRay& ir = rays.ray[k];
    const double weight = lens_image_weight(rays, ir, v, b);
    const double cos_a = dot(ir.w, v.normal_local);
    im.w[im.n] = ir.w;
    im.jacobian[im.n] = weight > 0.0 ? cos_a / weight : 0.0;
    im.weight[im.n] = weight;
    im.total += weight;
    ++im.n;
  }
  return im;
}

// The light strategy's draw among the images of light point b seen from v (LensConnection). The direct image
// (order 0) is solved; each later order's weight is estimated from one evaluation of the lens map at its Newton
// start (order 0's root, or the last order's start, moved on by the difference in Phi: one Newton step or two
// from its root), taken one Newton step on without evaluating again (LensMap::newton_estimate; where that step
// is too long to trust, the order is solved at once from there). Where P is Schwarzschild's cubic (and Kerr's
// proxies), an order past the first one evaluated (order 2, the first winding) is estimated from that order's start
// without an evaluation of its own (LensMap::extrapolated_estimate: Phi's slope in z relaxing to 1 along the
// branch), one evaluation of ~4.7 per light sample saved. An estimated order is solved only when it is drawn, or
// when a BSDF direction is matched against it. The probabilities weight / total are a function of v
// and B alone, so both strategies agree on them, and the drawn image's Jacobian is its own exact one: only
// which image to draw is estimated, never a density.
class LensImagePick {
 public:
  LensImagePick(const SphericalLens& lens, const LensVertex& v, const LensLight& b, int orders)
      : pair_(lens, v, b), v_(v), b_(b) {
    if (!pair_.ok()) return;
    pair_.frame(rays_);
    const LensMap& map = pair_.map();
    double z = map.direct_guess(pair_.gamma()), last_target = pair_.gamma();
    int evaluated = -1;  // the last order >= 1 whose start was evaluated
    for (int m = 0; m < std::min(orders, LensImages::kMax); ++m) {
      const double target = pair_.target(m);
      if (m > 0) z += target - last_target;
      last_target = target;
      LensImageRay& ir = rays_.ray[m];
      LensRay est;
      // from an earlier order's start without evaluating (start_[m] stays unset), else from this order's own
      bool estimated = evaluated > 0 &&
                       map.extrapolated_estimate(start_[evaluated], pair_.target(evaluated), target, est, guess_[m]);
      if (!estimated && m > 0) {
        start_[m] = map.start_at(z);
        evaluated = m;
        estimated = map.newton_estimate(start_[m], target, est);
      }
      if (estimated) {
        pair_.fill(v, m, est, ir);  // standing in for the image's until solved
      } else {  // order 0, or a start too far from the root to estimate from: solved now (from that start)
        const LensRay r = map.solve(target, z, &z, m > 0 ? &start_[m] : nullptr);
        if (!r.ok) break;
        pair_.fill(v, m, r, ir);
        solved_[m] = found_[m] = true;
      }
      weight[m] = lens_image_weight(rays_, ir, v, b);
      total += weight[m];
      n = m + 1;
    }
  }

  int n = 0;                                  // orders with a weight
  double weight[LensImages::kMax] = {};       // order 0's exact, the later ones' estimated
  double total = 0.0;

  // The azimuth the image of order k sweeps about the centre from v to B (after image(k) found it).
  double sweep(int k) const { return rays_.ray[k].r.phi; }

  // The image of order k solved: its direction at v and its exact area Jacobian |dA_B / dOmega_A|; false where
  // the map has no such root or the image brings nothing to v (from behind the surface or the light).
  bool image(int k, V3& w, double& jac) {
    LensImageRay& ir = rays_.ray[k];
    if (!solved_[k]) {
      const bool started = start_[k].z >= 0.0;  // (else an extrapolated estimate's z: a guess, not an evaluation)
      const LensRay r = pair_.map().solve(pair_.target(k), started ? -1.0 : guess_[k], nullptr,
                                          started ? &start_[k] : nullptr);
      solved_[k] = true;
      found_[k] = r.ok;
      if (r.ok) pair_.fill(v_, k, r, ir);
    }
    if (!found_[k]) return false;
    const double wk = lens_image_weight(rays_, ir, v_, b_);
    if (!(wk > 0.0)) return false;
    w = ir.w;
    jac = dot(ir.w, v_.normal_local) / wk;
    return jac > 0.0 && std::isfinite(jac);
  }

 private:
  LensPair pair_;
  LensVertex v_;
  LensLight b_;
  LensImageRays rays_;
  LensStart start_[LensImages::kMax];
  double guess_[LensImages::kMax] = {-1.0, -1.0, -1.0, -1.0};  // where an extrapolated estimate put the image
  bool solved_[LensImages::kMax] = {};
  bool found_[LensImages::kMax] = {};  // (solved and found)
};

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

template <class M>
class LensConnection {
 public:
  // With `proposal`, a metric with a lens proxy (Kerr) uses the proxy's connection as a proposal
  // (lens_proposal.h) where every light is planar, each light grown by the proposal's margin (`margin` false:
  // not grown), each orbit with the proxy's mass for its plane and sense (`plane_masses` false: the metric's).
  // With `focus`, a share of each planar light's points is drawn about the lens's focus (lens_focus.h; the mass of
  // the static metric's lens, or the proposal's), the rest by area.
  LensConnection(const M& m, const Scene& sc, int orders, bool proposal, bool margin = true,
                 bool plane_masses = true, bool focus = true)
      : sc_(sc), orders_(std::clamp(orders, 1, LensImages::kMax)) {
    if constexpr (M::kStaticSpherical) {
      lens_ = m.spherical_lens();
      focus_mass_ = lens_.throat ? 0.0 : std::max(0.0, -0.5 * lens_.a[1]);
    } else if constexpr (M::kLensProxy) {
      lens_ = m.lens_proxy();
      proposal_mass_ = lens_.cubic_mass();
      proposal_ = proposal && proposal_mass_ > 0.0 && !sc.lights.empty() &&
                  std::all_of(sc.lights.begin(), sc.lights.end(), [&](int p) { return proposal_light(sc, p); });
      if (proposal_) {
        proxy_mass_ = ProxyMass(proposal_mass_, plane_masses ? m.lens_proxy_spin() : V3{},
                                [&](double c) { return m.lens_proxy_mass(c); });
        const double own = margin ? m.lens_proxy_margin() : 0.0;
        for (int p : sc.lights) proposal_lights_.emplace_back(planar_light(sc, p), own);
        focus_mass_ = proposal_mass_;
      }
    }
    if (!focus) focus_mass_ = 0.0;
    if (focus_mass_ > 0.0 && !proposal_)  // (a proposal's focus draws over its grown lights)
      for (int p : sc.lights)
        planar_.push_back(proposal_light(sc, p) ? std::optional<PlanarLight>(planar_light(sc, p)) : std::nullopt);
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
  // and its pdf, with the point aimed at and the azimuth its image sweeps about the centre on the way (sweep; -1
  // as a proposal, whose images are the proxy's); u1, u2 pick the point, u3 the image.
  bool sample(const LensVertex& v, int li, double u1, double u2, double u3, V3& w, double& pdf, V3& target,
              double& sweep, double per) const {
    const int p = sc_.lights[li];
    sweep = -1.0;
    if (proposal_) return sample_proposal(v, li, u1, u2, u3, w, pdf, target, per);
    const LensFocus f = focus(v, li);
    LightPoint lp;
    const double q = f.share();
    if (u1 < q) {  // about the focus
      if (!f.point(u1 / q, u2, lp.pos) || !light_point_at(sc_, p, v.pos, lp.pos, lp)) return false;
    } else if (!sample_light_point(sc_, p, v.pos, q > 0.0 ? (u1 - q) / (1.0 - q) : u1, u2, lp)) {
      return false;
    }
    if (q > 0.0) lp.area = 1.0 / ((1.0 - q) / lp.area + f.density(lp.pos));
    LensImagePick pick(lens_, v, light(p, lp), orders_);
    if (!(pick.total > 0.0)) return false;
    const int k = pick_order(pick.weight, pick.n, pick.total, u3);
    double jac;
    if (!(pick.weight[k] > 0.0) || !pick.image(k, w, jac)) return false;
    pdf = pick.weight[k] / pick.total * jac / (lp.area * per);
    target = lp.pos;
    sweep = pick.sweep(k);
    return pdf > 0.0 && std::isfinite(pdf);
  }

  // Whether a light sample aimed at `target` on light prim p counts: its geodesic first hit that point (as a
  // proposal: that light, anywhere).
  bool light_sample_hits(const SegmentEnd& le, int p, V3 target) const {
    if (proposal_) return le.status == kHit && le.prim == p;
    return le.status == kHit && le.prim == p && hit_aim(le.pos, target);
  }

  // Solid-angle pdf with which the light strategy at v draws local direction w whose geodesic first hits
  // prim p at user-frame point x (0 if p is not a light or w not one of x's images of order < N; as a
  // proposal, whatever x: the pdf is that of the point where w's proxy orbit first crosses the light); the
  // lights chosen with probabilities sel (null: evenly).
  double pdf(const LensVertex& v, V3 w, int p, V3 x, const double* sel) const {
    const auto it = std::find(sc_.lights.begin(), sc_.lights.end(), p);
    if (p < 0 || it == sc_.lights.end()) return 0.0;
    const int li = int(it - sc_.lights.begin());
    const double p_light = sel ? sel[li] : 1.0 / double(sc_.light_count());
    if (proposal_) return p_light * proposal_pdf(v, w, li);
    LightPoint lp;
    if (!light_point_at(sc_, p, v.pos, x, lp)) return 0.0;
    const LensFocus f = focus(v, li);
    if (f.active()) lp.area = 1.0 / ((1.0 - f.share()) / lp.area + f.density(x));
    LensImagePick pick(lens_, v, light(p, lp), orders_);
    if (!(pick.total > 0.0)) return 0.0;
    for (int k = 0; k < pick.n; ++k) {  // nearest orders first: a BSDF direction is mostly the direct image
      V3 wk;
      double jac;
      if (pick.weight[k] > 0.0 && pick.image(k, wk, jac) && dot(wk, w) > 1.0 - kLensMatchCos)
        return p_light * pick.weight[k] / pick.total * jac / lp.area;
    }
    return 0.0;
  }

 private:
  // The image order drawn by u3 from weights weight[0 .. n) of sum total.
  static int pick_order(const double* weight, int n, double total, double u3) {
    double acc = 0.0;
    for (int i = 0; i < n; ++i) {
      acc += weight[i];
      if (u3 * total < acc) return i;
    }
    return n - 1;
  }

  // As a proposal: the proxy's mass for orbits about oriented normal `normal` (user frame; lens_proposal.h,
  // ProxyMass).
  double mass_about(V3 normal) const { return proxy_mass_.at(normal); }

  // As a proposal: where the proxy orbit from v along w first crosses light number li.
  LightCrossing crossing(const LensVertex& v, V3 w, int li) const {
    const PlanarLight& grown = proposal_lights_[size_t(li)].grown;
    return first_light_crossing([&](V3 nrm) { return mass_about(nrm); }, v.pos, v.radial_local, v.to_local, w,
                                grown, orders_);
  }

  // The proxy's draw among the images of light point B (number li) seen from v. The orders' weights (the
  // probabilities of drawing each) are those of the proxy map of the even orders' mass (the orbit turning about the
  // normal of the plane of the centre, v and B one way: order 0's exact, the later ones' estimated, as
  // LensImagePick's); an odd order's image turns the other way and is solved in the map of its own mass
  // (ProxyMass), built only when that image is drawn or matched (about one draw in ten). Weights are only the
  // draw's probabilities, a function of v and B, and each image's Jacobian is its own map's exact one.
  class ProposalPicks {
   public:
    ProposalPicks(const LensConnection& c, const LensVertex& v, int li, V3 B, double area) : v_(v) {
      const ProposalLight& L = c.proposal_lights_[size_t(li)];
      LightPoint lp;
      lp.pos = B;
      lp.normal = L.light.normal();
      lp.area = area;
      b_ = c.light(c.sc_.lights[li], lp);
      orders_ = c.orders_;
      const V3 nrm = normalize(cross(v.pos, B));  // the even orders' sense of rotation
      const double even = c.mass_about(nrm), odd = c.mass_about(-nrm);
      one_ = even == odd || !finite(nrm);
      if (one_) {
        own_[0].emplace(c.lens_, v, b_, orders_);
      } else {
        lens_[0] = SphericalLens::schwarzschild(even);
        lens_[1] = SphericalLens::schwarzschild(odd);
        own_[0].emplace(lens_[0], v, b_, orders_);
      }
      const LensImagePick& p = *own_[0];
      n = p.n;
      total = p.total;
      for (int m = 0; m < n; ++m) weight[m] = p.weight[m];
    }

    int n = 0;
    double weight[LensImages::kMax] = {};
    double total = 0.0;

    // The image of order k in its own mass's map (LensImagePick::image).
    bool image(int k, V3& w, double& jac) {
      if (one_ || k % 2 == 0) return own_[0]->image(k, w, jac);
      if (!own_[1]) own_[1].emplace(lens_[1], v_, b_, orders_);
      return k < own_[1]->n && own_[1]->image(k, w, jac);
    }

   private:
    LensVertex v_;
    LensLight b_;
    int orders_ = 1;
    bool one_ = true;
    SphericalLens lens_[2];  // (the picks' lens maps refer to them)
    std::optional<LensImagePick> own_[2];
  };

  bool sample_proposal(const LensVertex& v, int li, double u1, double u2, double u3, V3& w, double& pdf,
                       V3& target, double per) const {
    const ProposalLight& L = proposal_lights_[size_t(li)];
    const LensFocus f = focus(v, li);
    const double q = f.share();
    V3 B;
    if (u1 < q) {  // about the focus
      if (!f.point(u1 / q, u2, B)) return false;
    } else {
      B = L.point(q > 0.0 ? (u1 - q) / (1.0 - q) : u1, u2);
    }
    const double area = 1.0 / ((1.0 - q) * L.density(B) + f.density(B));
    ProposalPicks pk(*this, v, li, B, area);
    if (!(pk.total > 0.0)) return false;
    const int k = pick_order(pk.weight, pk.n, pk.total, u3);
    double jac;
    if (!(pk.weight[k] > 0.0) || !pk.image(k, w, jac)) return false;
    pdf = pk.weight[k] / pk.total * jac / (area * per);
    target = B;
    // it counts only if its proxy orbit crosses the light first at B
    const LightCrossing x = crossing(v, w, li);
    if (!x.ok || length(x.pos - B) > 1e-6 * (1.0 + length(B))) return false;
    return pdf > 0.0 && std::isfinite(pdf);
  }

  double proposal_pdf(const LensVertex& v, V3 w, int li) const {
    const LightCrossing c = crossing(v, w, li);
    if (!c.ok) return 0.0;
    const LensFocus f = focus(v, li);
    const double area = 1.0 / ((1.0 - f.share()) * proposal_lights_[size_t(li)].density(c.pos) + f.density(c.pos));
    ProposalPicks pk(*this, v, li, c.pos, area);
    if (!(pk.total > 0.0)) return 0.0;
    for (int k = 0; k < pk.n; ++k) {  // nearest orders first: a BSDF direction is mostly the direct image
      V3 wk;
      double jac;
      if (pk.weight[k] > 0.0 && pk.image(k, wk, jac) && dot(wk, w) > 1.0 - kLensMatchCos)
        return pk.weight[k] / pk.total * jac / area;
    }
    return 0.0;
  }

  // The focus of light number li seen from v (lens_focus.h) over the outline its points are drawn from (the light;
  // as a proposal, the light grown by its margin); inactive for a light that is not planar, or without a mass.
  LensFocus focus(const LensVertex& v, int li) const {
    if (!(focus_mass_ > 0.0)) return {};
    if (proposal_) return LensFocus(focus_mass_, v.pos, proposal_lights_[size_t(li)].grown);
    const std::optional<PlanarLight>& L = planar_[size_t(li)];
    return L ? LensFocus(focus_mass_, v.pos, *L) : LensFocus{};
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
  ProxyMass proxy_mass_;  // as a proposal: the proxy's mass by the orbit's plane and sense
  std::vector<ProposalLight> proposal_lights_;  // as a proposal: each light and its margin
  double focus_mass_ = 0.0;                     // the mass whose focus draws light points (0: none)
  std::vector<std::optional<PlanarLight>> planar_;  // (a static metric's focus) each light, where planar
};

}  // namespace wv
