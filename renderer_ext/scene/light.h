// Light sampling for the light connection in curved space.
//
// At a hit point x the integrator needs directions (in the local observer frame) that tend to reach the
// lights. The geodesic actually reaching a light is unknown in advance, so the sampled direction comes
// from a *proxy*: the light seen as if space were flat, i.e. the light's displacement from x mapped into
// the local frame by the linear map L (local = L * user-frame displacement). Sampling and the pdf both
// use the same proxy, so the proxy is just a probability density over local directions and the
// estimator stays unbiased whatever the geodesic then hits; bending only costs variance.
//
// Quads and disks are sampled uniformly by area on their affine image under L (pdf = dist^2 / (A' cos')),
// spheres uniformly in the cone subtended by the sphere.
#pragma once

#include <cmath>

#include "core/vec3.h"
#include "scene/scene.h"

namespace wv {

struct LinearMap {
  double m[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  V3 operator()(V3 v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
};

namespace detail {

inline double one_minus_cos(double sin2) { return sin2 / (1.0 + std::sqrt(std::max(0.0, 1.0 - sin2))); }

// Solves o + s a + r b = tau w; false if degenerate.
inline bool plane_solve(V3 o, V3 a, V3 b, V3 w, double& s, double& r, double& tau) {
  const V3 mw = -w;
  const double det = dot(a, cross(b, mw));
  if (det == 0.0 || !std::isfinite(det)) return false;
  const V3 rhs = -o;
  s = dot(rhs, cross(b, mw)) / det;
  r = dot(a, cross(rhs, mw)) / det;
  tau = dot(a, cross(b, rhs)) / det;
  return true;
}

}  // namespace detail

// Samples a local direction towards light prim p from user-frame point x. Returns false on failure.
inline bool sample_light(const Scene& sc, int p, V3 x, const LinearMap& L, double u1, double u2, V3& w,
                         double& pdf) {
  const Prim& pr = sc.prims[p];
  if (pr.kind == PrimKind::kSphere) {
    const Sphere& s = sc.spheres[pr.index];
    const V3 dc = s.center - x;
    const double D2 = dot(dc, dc);
    if (D2 <= s.radius * s.radius) return false;
    const V3 axis = normalize(L(dc));
    const double sin2 = s.radius * s.radius / D2;
    const double omc = detail::one_minus_cos(sin2);  // 1 - cos(theta_max)
    const double om = u1 * omc, cos_t = 1.0 - om, sin_t = std::sqrt(std::max(0.0, om * (2.0 - om)));
    const double phi = kTwoPi * u2;
    V3 t, b;
    basis_around(axis, t, b);
    w = axis * cos_t + t * (sin_t * std::cos(phi)) + b * (sin_t * std::sin(phi));
    pdf = 1.0 / (kTwoPi * omc);
    return true;
  }
  V3 q, la, lb;
  double area;
  if (pr.kind == PrimKind::kQuad) {
    const Quad& qd = sc.quads[pr.index];
    q = L(qd.corner + qd.eu * u1 + qd.ev * u2 - x);
    la = L(qd.eu);
    lb = L(qd.ev);
    area = length(cross(la, lb));
  } else {  // disk
    const Disk& k = sc.disks[pr.index];
    const double rho = std::sqrt(k.r_in * k.r_in + u1 * (k.r_out * k.r_out - k.r_in * k.r_in));
    const double phi = kTwoPi * u2;
    q = L(k.center + k.axis_u * (rho * std::cos(phi)) + k.axis_v * (rho * std::sin(phi)) - x);
    la = L(k.axis_u);
    lb = L(k.axis_v);
    area = M_PI * (k.r_out * k.r_out - k.r_in * k.r_in) * length(cross(la, lb));
  }
  const double d2 = dot(q, q);
  if (!(d2 > 0.0)) return false;
  w = q / std::sqrt(d2);
  const double c = std::fabs(dot(w, normalize(cross(la, lb))));
  if (!(c > 1e-9) || !(area > 0.0)) return false;
  pdf = d2 / (area * c);
  return std::isfinite(pdf);
}

// Solid-angle pdf with which sample_light(p, x, L) produces local direction w.
inline double light_pdf(const Scene& sc, int p, V3 x, const LinearMap& L, V3 w) {
  const Prim& pr = sc.prims[p];
  if (pr.kind == PrimKind::kSphere) {
    const Sphere& s = sc.spheres[pr.index];
    const V3 dc = s.center - x;
    const double D2 = dot(dc, dc);
    if (D2 <= s.radius * s.radius) return 0.0;
    const double sin2 = s.radius * s.radius / D2;
    const double omc = detail::one_minus_cos(sin2);
    if (1.0 - dot(w, normalize(L(dc))) > omc) return 0.0;
    return 1.0 / (kTwoPi * omc);
  }
  V3 o, la, lb;
  double area_scale;
  double s, r, tau;
  if (pr.kind == PrimKind::kQuad) {
    const Quad& qd = sc.quads[pr.index];
    o = L(qd.corner - x);
    la = L(qd.eu);
    lb = L(qd.ev);
    if (!detail::plane_solve(o, la, lb, w, s, r, tau)) return 0.0;
    if (tau <= 0.0 || s < 0.0 || s > 1.0 || r < 0.0 || r > 1.0) return 0.0;
    area_scale = 1.0;
  } else {
    const Disk& k = sc.disks[pr.index];
    o = L(k.center - x);
    la = L(k.axis_u);
    lb = L(k.axis_v);
    if (!detail::plane_solve(o, la, lb, w, s, r, tau)) return 0.0;
    const double rho2 = s * s + r * r;
    if (tau <= 0.0 || rho2 < k.r_in * k.r_in || rho2 > k.r_out * k.r_out) return 0.0;
    area_scale = M_PI * (k.r_out * k.r_out - k.r_in * k.r_in);
  }
  const V3 nrm = cross(la, lb);
  const double area = area_scale * length(nrm);
  const double c = std::fabs(dot(w, normalize(nrm)));
  if (!(c > 1e-9) || !(area > 0.0)) return 0.0;
  return tau * tau / (area * c);
}

}  // namespace wv
