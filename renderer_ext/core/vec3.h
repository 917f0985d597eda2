// Small 3-vector for scene geometry and shading (Cartesian user frame or a local observer frame).
#pragma once

#include <algorithm>
#include <cmath>

namespace wv {

struct V3 {
  double x = 0, y = 0, z = 0;
  V3() = default;
  constexpr V3(double a, double b, double c) : x(a), y(b), z(c) {}
  explicit V3(const double* p) : x(p[0]), y(p[1]), z(p[2]) {}
  double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  double& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  void store(double* p) const { p[0] = x; p[1] = y; p[2] = z; }
};

inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator-(V3 a) { return {-a.x, -a.y, -a.z}; }
inline V3 operator*(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline V3 operator*(double s, V3 a) { return a * s; }
inline V3 operator*(V3 a, V3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
inline V3 operator/(V3 a, double s) { return a * (1.0 / s); }
inline V3& operator+=(V3& a, V3 b) { return a = a + b; }
inline V3& operator*=(V3& a, V3 b) { return a = a * b; }
inline V3& operator*=(V3& a, double s) { return a = a * s; }
inline double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline double length(V3 a) { return std::sqrt(dot(a, a)); }
inline V3 normalize(V3 a) {
  const double n = length(a);
  return n > 0.0 ? a / n : V3{0, 0, 0};
}
inline double max_component(V3 a) { return std::max(a.x, std::max(a.y, a.z)); }
inline V3 vmin(V3 a, V3 b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
inline V3 vmax(V3 a, V3 b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }
inline bool finite(V3 a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }

// Orthonormal basis (t, b, n) around unit n, continuous in n except at n = +-g for a fixed generic
// direction g. (Constructions that switch on the sign of a component are discontinuous on a whole
// coordinate plane, where axis-aligned walls sit: a normal perturbed by 1e-17 would then get another
// tangent frame and turn the same random numbers into another direction.)
inline void basis_around(V3 n, V3& t, V3& b) {
  const V3 g{0.2672612419124244, 0.5345224838248488, 0.8017837257372732};  // (1, 2, 3) / sqrt(14)
  V3 c = cross(g, n);
  double len = length(c);
  if (len < 1e-6) {  // n (anti)parallel to g: any perpendicular will do
    c = cross(V3{1, 0, 0}, n);
    len = length(c);
  }
  t = c / len;
  b = cross(n, t);
}

}  // namespace wv
