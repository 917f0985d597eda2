// Scene primitives in the user's Cartesian frame: spheres, parallelograms (quads), annular disks and
// triangles. Each can be intersected with a straight segment, has an implicit function whose zero set is
// the surface (used to refine hits of curved rays on the dense output), and gives the geometric normal
// and texture coordinates at a surface point.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/vec3.h"

namespace wv {

enum class PrimKind : uint8_t { kSphere = 0, kQuad = 1, kDisk = 2, kTriangle = 3 };

struct Sphere {
  V3 center;
  double radius;
  V3 pole, meridian, third;  // orthonormal frame for texture coordinates
};

struct Quad {
  V3 corner, eu, ev, normal;  // normal = normalize(eu x ev)
  double area;
  // Dual edge vectors: a point p of the plane is corner + s eu + r ev with s = (p - corner).du and
  // r = (p - corner).dv (make_quad), which the intersection test uses instead of solving for them.
  V3 du, dv;
};

// A quad with corner c and edges eu, ev (not parallel), its normal, area and dual edges filled in.
inline Quad make_quad(V3 c, V3 eu, V3 ev) {
  Quad q;
  q.corner = c;
  q.eu = eu;
  q.ev = ev;
  const V3 n = cross(eu, ev);
  q.area = length(n);
  q.normal = n / q.area;
  const double uu = dot(eu, eu), uv = dot(eu, ev), vv = dot(ev, ev), det = uu * vv - uv * uv;
  q.du = (eu * vv - ev * uv) / det;
  q.dv = (ev * uu - eu * uv) / det;
  return q;
}

struct Disk {
  V3 center, normal, axis_u, axis_v;  // axis_u = meridian projected into the plane
  double r_in, r_out;
};

struct Triangle {
  V3 a, e1, e2, normal;             // vertices a, a + e1, a + e2
  double uv[3][2];                   // texture coordinates of the three vertices
};

// One entry of the scene's primitive list (what the BVH indexes).
struct Prim {
  PrimKind kind;
  int32_t index;     // into the scene's array of that kind
  int32_t material;
  int32_t shape;     // the user's shape (a mesh is one shape of many triangles)
  int8_t sheet;      // Ellis sheet the primitive lives on (+1 / -1)
};

struct SurfacePoint {
  V3 normal;  // unit geometric normal, user frame
  double u = 0, v = 0;
};

constexpr double kTwoPi = 6.283185307179586;

// --- a disk's area and points, in units of its axes (which a scene may scale) ---------------------------

inline double disk_area(const Disk& k) {
  return M_PI * (k.r_out * k.r_out - k.r_in * k.r_in) * length(cross(k.axis_u, k.axis_v));
}
// The radius between lo and hi at which u in [0, 1) puts a point drawn uniformly by area.
inline double disk_radius(double lo, double hi, double u) { return std::sqrt(lo * lo + u * (hi * hi - lo * lo)); }
// The point of disk k's plane at radius rho and angle phi from axis_u.
inline V3 disk_point(const Disk& k, double rho, double phi) {
  return k.center + k.axis_u * (rho * std::cos(phi)) + k.axis_v * (rho * std::sin(phi));
}
// The squared radius of point x of disk k's plane.
inline double disk_radius2(const Disk& k, V3 x) {
  const V3 d = x - k.center;
  const double a = dot(d, k.axis_u) / dot(k.axis_u, k.axis_u), b = dot(d, k.axis_v) / dot(k.axis_v, k.axis_v);
  return a * a + b * b;
}

// --- segment intersection: o + t d, t in (tmin, tmax); returns the smallest such t --------------------

inline bool intersect(const Sphere& s, V3 o, V3 d, double tmin, double tmax, double& t) {
  const V3 oc = o - s.center;
  const double a = dot(d, d), b = dot(oc, d), c = dot(oc, oc) - s.radius * s.radius;
  const double disc = b * b - a * c;
  if (disc < 0.0 || a == 0.0) return false;
  const double sq = std::sqrt(disc);
  // numerically stable roots
  const double q = b >= 0.0 ? -(b + sq) : -(b - sq);
  double t0 = q / a, t1 = q != 0.0 ? c / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  if (t0 > tmin && t0 < tmax) { t = t0; return true; }
  if (t1 > tmin && t1 < tmax) { t = t1; return true; }
  return false;
}

// Parallelogram-plane coordinates of point p: p = corner + s eu + r ev (least squares in the plane).
inline void plane_coords(V3 p, V3 origin, V3 eu, V3 ev, double& s, double& r) {
  const V3 w = p - origin;
  const double uu = dot(eu, eu), uv = dot(eu, ev), vv = dot(ev, ev);
  const double wu = dot(w, eu), wv = dot(w, ev), det = uu * vv - uv * uv;
  s = (vv * wu - uv * wv) / det;
  r = (uu * wv - uv * wu) / det;
}

inline bool intersect(const Quad& q, V3 o, V3 d, double tmin, double tmax, double& t) {
  const double dn = dot(d, q.normal);
  if (dn == 0.0) return false;
  const double tt = dot(q.corner - o, q.normal) / dn;
  if (!(tt > tmin && tt < tmax)) return false;
  const V3 w = o + d * tt - q.corner;
  const double s = dot(w, q.du), r = dot(w, q.dv);
  if (s < 0.0 || s > 1.0 || r < 0.0 || r > 1.0) return false;
  t = tt;
  return true;
}

inline bool intersect(const Disk& k, V3 o, V3 d, double tmin, double tmax, double& t) {
  const double dn = dot(d, k.normal);
  if (dn == 0.0) return false;
  const double tt = dot(k.center - o, k.normal) / dn;
  if (!(tt > tmin && tt < tmax)) return false;
  const V3 w = o + d * tt - k.center;
  const double rho2 = dot(w, w) - std::pow(dot(w, k.normal), 2);
  if (rho2 < k.r_in * k.r_in || rho2 > k.r_out * k.r_out) return false;
  t = tt;
  return true;
}

// Moller-Trumbore.
inline bool intersect(const Triangle& tr, V3 o, V3 d, double tmin, double tmax, double& t) {
  const V3 pv = cross(d, tr.e2);
  const double det = dot(tr.e1, pv);
  if (det == 0.0) return false;
  const double inv = 1.0 / det;
  const V3 tv = o - tr.a;
  const double b1 = dot(tv, pv) * inv;
  if (b1 < 0.0 || b1 > 1.0) return false;
  const V3 qv = cross(tv, tr.e1);
  const double b2 = dot(d, qv) * inv;
  if (b2 < 0.0 || b1 + b2 > 1.0) return false;
  const double tt = dot(tr.e2, qv) * inv;
  if (!(tt > tmin && tt < tmax)) return false;
  t = tt;
  return true;
}

// --- implicit functions: zero on the surface, sign tells the side ------------------------------------

inline double implicit(const Sphere& s, V3 p) { return length(p - s.center) - s.radius; }
inline double implicit(const Quad& q, V3 p) { return dot(p - q.corner, q.normal); }
inline double implicit(const Disk& k, V3 p) { return dot(p - k.center, k.normal); }
inline double implicit(const Triangle& tr, V3 p) { return dot(p - tr.a, tr.normal); }

// A lower bound on the distance, within its plane, from point x of the plane to a flat primitive (<= 0
// inside it): how far a crossing of the plane found approximately may lie from it and still miss.
inline double plane_gap(const Quad& q, V3 x) {
  const V3 w = x - q.corner;
  const double s = dot(w, q.du), r = dot(w, q.dv);
  return std::max(std::max(-s, s - 1.0) / length(q.du), std::max(-r, r - 1.0) / length(q.dv));
}
inline double plane_gap(const Disk& k, V3 x) {
  const V3 w = x - k.center;
  const double rho = std::sqrt(std::max(0.0, dot(w, w) - dot(w, k.normal) * dot(w, k.normal)));
  return std::max(rho - k.r_out, k.r_in - rho);
}
inline double plane_gap(const Triangle& tr, V3 x) {
  // barycentric coordinates as linear functions of x in the plane: b1 = (x - a).g1, b2 = (x - a).g2
  const V3 g1 = cross(tr.e2, tr.normal) * (1.0 / dot(tr.e1, cross(tr.e2, tr.normal)));
  const V3 g2 = cross(tr.normal, tr.e1) * (1.0 / dot(tr.e2, cross(tr.normal, tr.e1)));
  const V3 w = x - tr.a;
  const double b1 = dot(w, g1), b2 = dot(w, g2);
  return std::max(std::max(-b1 / length(g1), -b2 / length(g2)), (b1 + b2 - 1.0) / length(g1 + g2));
}

// --- normal and texture coordinates at a surface point ------------------------------------------------

inline SurfacePoint surface_at(const Sphere& s, V3 p) {
  SurfacePoint sp;
  const V3 n = normalize(p - s.center);
  sp.normal = n;
  const double cz = std::max(-1.0, std::min(1.0, dot(n, s.pole)));
  double phi = std::atan2(dot(n, s.third), dot(n, s.meridian));
  if (phi < 0.0) phi += kTwoPi;
  sp.u = phi / kTwoPi;
  sp.v = 1.0 - std::acos(cz) / M_PI;
  return sp;
}

inline SurfacePoint surface_at(const Quad& q, V3 p) {
  SurfacePoint sp;
  sp.normal = q.normal;
  plane_coords(p, q.corner, q.eu, q.ev, sp.u, sp.v);
  return sp;
}

inline SurfacePoint surface_at(const Disk& k, V3 p) {
  SurfacePoint sp;
  sp.normal = k.normal;
  const V3 w = p - k.center;
  const double a = dot(w, k.axis_u), b = dot(w, k.axis_v);
  const double rho = std::sqrt(a * a + b * b);
  sp.u = k.r_out > k.r_in ? (rho - k.r_in) / (k.r_out - k.r_in) : 0.0;
  double phi = std::atan2(b, a);
  if (phi < 0.0) phi += kTwoPi;
  sp.v = phi / kTwoPi;
  return sp;
}

inline SurfacePoint surface_at(const Triangle& tr, V3 p) {
  SurfacePoint sp;
  sp.normal = tr.normal;
  double b1, b2;
  plane_coords(p, tr.a, tr.e1, tr.e2, b1, b2);
  const double b0 = 1.0 - b1 - b2;
  sp.u = b0 * tr.uv[0][0] + b1 * tr.uv[1][0] + b2 * tr.uv[2][0];
  sp.v = b0 * tr.uv[0][1] + b1 * tr.uv[1][1] + b2 * tr.uv[2][1];
  return sp;
}

// --- bounds -------------------------------------------------------------------------------------------

struct Box {
  V3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  void extend(V3 p) { lo = vmin(lo, p); hi = vmax(hi, p); }
  void extend(const Box& b) { lo = vmin(lo, b.lo); hi = vmax(hi, b.hi); }
  V3 centroid() const { return (lo + hi) * 0.5; }
  double area() const {
    const V3 e = hi - lo;
    return e.x < 0 ? 0.0 : 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
};

inline Box bounds(const Sphere& s) {
  Box b;
  const V3 r{s.radius, s.radius, s.radius};
  b.extend(s.center - r);
  b.extend(s.center + r);
  return b;
}
inline Box bounds(const Quad& q) {
  Box b;
  b.extend(q.corner);
  b.extend(q.corner + q.eu);
  b.extend(q.corner + q.ev);
  b.extend(q.corner + q.eu + q.ev);
  return b;
}
inline Box bounds(const Disk& k) {
  Box b;
  // extent of a circle of radius R with normal n along axis i: R sqrt(1 - n_i^2)
  for (int i = 0; i < 3; ++i) {
    const double e = k.r_out * std::sqrt(std::max(0.0, 1.0 - k.normal[i] * k.normal[i]));
    V3 lo = k.center, hi = k.center;
    lo[i] -= e;
    hi[i] += e;
    b.extend(lo);
    b.extend(hi);
  }
  return b;
}
inline Box bounds(const Triangle& t) {
  Box b;
  b.extend(t.a);
  b.extend(t.a + t.e1);
  b.extend(t.a + t.e2);
  return b;
}

}  // namespace wv
