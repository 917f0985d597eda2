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
// optionally scaled about their centre by `scale` (a margin for a lensed image larger than the light),
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

// The cone a sphere light subtends from x, around its centre's direction in the local frame.
struct ConeProxy {
  bool valid = false;  // false: x lies inside the sphere
  V3 axis;
  double omc = 0.0;  // 1 - cos(half angle)
  double pdf() const { return 1.0 / (kTwoPi * omc); }
};

inline void cone_proxy(const Sphere& s, V3 x, const LinearMap& L, ConeProxy& c) {
  const V3 dc = s.center - x;
  const double D2 = dot(dc, dc);
  c.valid = D2 > s.radius * s.radius;
  if (!c.valid) return;
  c.axis = normalize(L(dc));
  c.omc = one_minus_cos(s.radius * s.radius / D2);
}

// A quad or disk light as seen from x in the local frame: its points are o + s la + r lb with (s, r) in
// [0, 1]^2 (quad) or in the annulus r_in <= |(s, r)| <= r_out (disk, la and lb the images of its axes).
struct PlanarProxy {
  V3 o, la, lb;
  bool disk = false;
  double r_in = 0.0, r_out = 0.0;
  double area = 0.0;  // area of the image of the light under L
  V3 normal;          // unit normal of that image

  bool contains(double s, double r) const {
    if (!disk) return s >= 0.0 && s <= 1.0 && r >= 0.0 && r <= 1.0;
    const double rho2 = s * s + r * r;
    return rho2 >= r_in * r_in && rho2 <= r_out * r_out;
  }
  // Solid-angle pdf of uniform area sampling for direction w reaching the image at distance^2 d2.
  double pdf(V3 w, double d2) const {
    const double c = std::fabs(dot(w, normal));
    if (!(c > 1e-9) || !(area > 0.0)) return 0.0;
    return d2 / (area * c);
  }
};

// (Filled in place: a vertex's proxies live in its Aim, which is not cleared for each.)
inline void planar_proxy(const Scene& sc, const Prim& pr, V3 x, const LinearMap& L, double scale, PlanarProxy& q) {
  if (pr.kind == PrimKind::kQuad) {
    const Quad& qd = sc.quads[pr.index];
    q.o = L(qd.corner - (qd.eu + qd.ev) * (0.5 * (scale - 1.0)) - x);  // scaled about its centre
    q.la = L(qd.eu * scale);
    q.lb = L(qd.ev * scale);
    q.disk = false;
    q.r_in = q.r_out = 0.0;
  } else {
    const Disk& k = sc.disks[pr.index];
    q.o = L(k.center - x);
    q.la = L(k.axis_u * scale);
    q.lb = L(k.axis_v * scale);
    q.disk = true;
    q.r_in = k.r_in;
    q.r_out = k.r_out;
  }
  const V3 n = cross(q.la, q.lb);
  const double len = length(n);
  q.normal = len > 0.0 ? n / len : V3{0, 0, 0};
  q.area = q.disk ? M_PI * (q.r_out * q.r_out - q.r_in * q.r_in) * len : len;
}

}  // namespace detail

// Light prim p's proxy as seen from user-frame point x through the linear map L (scaled by `scale` about its
// centre where it is a quad or disk): what sampling a direction and its pdf both read, so a vertex computes
// it once for its light sample and the pdfs of both strategies' directions.
struct LightProxy {
  bool sphere = false;
  detail::ConeProxy cone;      // sphere
  detail::PlanarProxy planar;  // quad or disk
};

inline void light_proxy(const Scene& sc, int p, V3 x, const LinearMap& L, double scale, LightProxy& q) {
  const Prim& pr = sc.prims[p];
  q.sphere = pr.kind == PrimKind::kSphere;
  if (q.sphere) {
    detail::cone_proxy(sc.spheres[pr.index], x, L, q.cone);
  } else {
    detail::planar_proxy(sc, pr, x, L, scale, q.planar);
  }
}
inline LightProxy light_proxy(const Scene& sc, int p, V3 x, const LinearMap& L) {
  LightProxy q;
  light_proxy(sc, p, x, L, 1.0, q);
  return q;
}

// Samples a local direction from a light's proxy. Returns false on failure.
inline bool sample_light(const LightProxy& lq, double u1, double u2, V3& w, double& pdf) {
  if (lq.sphere) {
    const detail::ConeProxy& c = lq.cone;
    if (!c.valid) return false;
    const double om = u1 * c.omc, cos_t = 1.0 - om, sin_t = std::sqrt(std::max(0.0, om * (2.0 - om)));
    const double phi = kTwoPi * u2;
    V3 t, b;
    basis_around(c.axis, t, b);
    w = c.axis * cos_t + t * (sin_t * std::cos(phi)) + b * (sin_t * std::sin(phi));
    pdf = c.pdf();
    return true;
  }
  const detail::PlanarProxy& q = lq.planar;
  double s = u1, r = u2;  // quad: uniform in [0, 1]^2; disk: uniform by area in the annulus
  if (q.disk) {
    const double rho = std::sqrt(q.r_in * q.r_in + u1 * (q.r_out * q.r_out - q.r_in * q.r_in));
    const double phi = kTwoPi * u2;
    s = rho * std::cos(phi);
    r = rho * std::sin(phi);
  }
  const V3 v = q.o + q.la * s + q.lb * r;
  const double d2 = dot(v, v);
  if (!(d2 > 0.0)) return false;
  w = v / std::sqrt(d2);
  pdf = q.pdf(w, d2);
  return pdf > 0.0 && std::isfinite(pdf);
}

// A point on light prim p drawn uniformly by area (user frame), with the light's unit normal there and the
// area sampled: what the lens-aware connection (integrators/lens_connection.h) starts from. A sphere is
// sampled on the hemisphere that faces `from` (the other half is behind it, as seen in flat space; light
// bent round it from there is left to BSDF sampling).
struct LightPoint {
  V3 pos, normal;
  double area = 0.0;
};
inline bool sample_light_point(const Scene& sc, int p, V3 from, double u1, double u2, LightPoint& lp) {
  const Prim& pr = sc.prims[p];
  if (pr.kind == PrimKind::kQuad) {
    const Quad& q = sc.quads[pr.index];
    lp.pos = q.corner + q.eu * u1 + q.ev * u2;
    lp.normal = q.normal;
    lp.area = length(cross(q.eu, q.ev));
  } else if (pr.kind == PrimKind::kDisk) {
    const Disk& k = sc.disks[pr.index];
    lp.pos = disk_point(k, disk_radius(k.r_in, k.r_out, u1), kTwoPi * u2);
    lp.normal = k.normal;
    lp.area = disk_area(k);
  } else if (pr.kind == PrimKind::kSphere) {
    const Sphere& s = sc.spheres[pr.index];
    const V3 axis = normalize(from - s.center);
    if (!finite(axis)) return false;
    V3 t, b;
    basis_around(axis, t, b);
    const double z = u1, rxy = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = kTwoPi * u2;  // uniform on the cap
    lp.normal = axis * z + t * (rxy * std::cos(phi)) + b * (rxy * std::sin(phi));
    lp.pos = s.center + lp.normal * s.radius;
    lp.area = kTwoPi * s.radius * s.radius;
  } else {
    return false;
  }
  return lp.area > 0.0 && std::isfinite(lp.area);
}

// The unit normal and sampled area of light prim p at user-frame point x on it, seen from `from`; false
// where sample_light_point never lands.
inline bool light_point_at(const Scene& sc, int p, V3 from, V3 x, LightPoint& lp) {
  const Prim& pr = sc.prims[p];
  lp.pos = x;
  if (pr.kind == PrimKind::kQuad) {
    const Quad& q = sc.quads[pr.index];
    lp.normal = q.normal;
    lp.area = length(cross(q.eu, q.ev));
  } else if (pr.kind == PrimKind::kDisk) {
    const Disk& k = sc.disks[pr.index];
    lp.normal = k.normal;
    lp.area = disk_area(k);
  } else if (pr.kind == PrimKind::kSphere) {
    const Sphere& s = sc.spheres[pr.index];
    lp.normal = normalize(x - s.center);
    if (!(dot(lp.normal, from - s.center) > 0.0)) return false;
    lp.area = kTwoPi * s.radius * s.radius;
  } else {
    return false;
  }
  return lp.area > 0.0 && std::isfinite(lp.area);
}

// The numbers (u1, u2) in [0, 1)^2 with which sample_light_point(sc, p, from, u1, u2) draws user-frame point x of
// light prim p (sample_light_point's inverse); false where it never lands there.
inline bool light_point_uv(const Scene& sc, int p, V3 from, V3 x, double& u1, double& u2) {
  const Prim& pr = sc.prims[p];
  auto wrap = [](double a) { return a - std::floor(a); };
  if (pr.kind == PrimKind::kQuad) {
    const Quad& q = sc.quads[pr.index];
    u1 = dot(x - q.corner, q.du);
    u2 = dot(x - q.corner, q.dv);
  } else if (pr.kind == PrimKind::kDisk) {
    const Disk& k = sc.disks[pr.index];
    const V3 d = x - k.center;
    const double a = dot(d, k.axis_u) / dot(k.axis_u, k.axis_u), b = dot(d, k.axis_v) / dot(k.axis_v, k.axis_v);
    u1 = (a * a + b * b - k.r_in * k.r_in) / (k.r_out * k.r_out - k.r_in * k.r_in);
    u2 = wrap(std::atan2(b, a) / kTwoPi);
  } else if (pr.kind == PrimKind::kSphere) {
    const Sphere& s = sc.spheres[pr.index];
    const V3 axis = normalize(from - s.center), n = normalize(x - s.center);
    if (!finite(axis) || !finite(n)) return false;
    V3 t, b;
    basis_around(axis, t, b);
    u1 = dot(n, axis);
    u2 = wrap(std::atan2(dot(n, b), dot(n, t)) / kTwoPi);
  } else {
    return false;
  }
  return u1 >= 0.0 && u1 <= 1.0 && u2 >= 0.0 && u2 <= 1.0;
}

// Solid-angle pdf with which sample_light(lq, ...) produces local direction w.
inline double light_pdf(const LightProxy& lq, V3 w) {
  if (lq.sphere) {
    const detail::ConeProxy& c = lq.cone;
    if (!c.valid || 1.0 - dot(w, c.axis) > c.omc) return 0.0;
    return c.pdf();
  }
  const detail::PlanarProxy& q = lq.planar;
  double s, r, tau;
  if (!detail::plane_solve(q.o, q.la, q.lb, w, s, r, tau) || tau <= 0.0 || !q.contains(s, r)) return 0.0;
  return q.pdf(w, tau * tau);
}

}  // namespace wv
