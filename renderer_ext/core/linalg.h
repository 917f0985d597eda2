// Small dense linear algebra: 4x4 inverses, a 3x3 inverse, 3x3 symmetric inverse square root.
#pragma once

#include <cmath>
#include <utility>

namespace wv {

// Inverts a 3x3 matrix by cofactors. Returns false if singular (or not finite).
inline bool invert3(const double m[3][3], double inv[3][3]) {
  const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                     m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                     m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
  if (!(std::fabs(det) > 0.0) || !std::isfinite(det)) return false;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {  // the cofactor of (j, i) over the determinant
      const int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
      inv[i][j] = (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]) / det;
    }
  return true;
}

// Inverts a 4x4 matrix by Gauss-Jordan elimination with partial pivoting. Returns false if singular.
inline bool invert4(const double a[4][4], double inv[4][4]) {
  double m[4][8];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      m[i][j] = a[i][j];
      m[i][j + 4] = (i == j) ? 1.0 : 0.0;
    }
  for (int c = 0; c < 4; ++c) {
    int piv = c;
    for (int r = c + 1; r < 4; ++r)
      if (std::fabs(m[r][c]) > std::fabs(m[piv][c])) piv = r;
    if (!(std::fabs(m[piv][c]) > 0.0)) return false;
    if (piv != c)
      for (int j = 0; j < 8; ++j) std::swap(m[c][j], m[piv][j]);
    const double s = 1.0 / m[c][c];
    for (int j = 0; j < 8; ++j) m[c][j] *= s;
    for (int r = 0; r < 4; ++r) {
      if (r == c) continue;
      const double f = m[r][c];
      if (f == 0.0) continue;
      for (int j = 0; j < 8; ++j) m[r][j] -= f * m[c][j];
    }
  }
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) inv[i][j] = m[i][j + 4];
  return true;
}

// The inverse of a 4x4 matrix by cofactors (2x2 sub-determinants), for any value type T with + - * /:
// double, Dual<N> and Lanes alike. Branch-free, so it runs in SIMD lanes and gives exact derivatives
// through duals, where invert4's pivoting cannot; no singularity check (a metric generated from its line
// element, warpviz/spacetime/line_element/codegen.py, inverts g_{mu nu} here once per right-hand side).
template <class T>
inline void cofactor_inverse4(const T m[4][4], T out[4][4]) {
  const T s0 = m[0][0] * m[1][1] - m[1][0] * m[0][1], s1 = m[0][0] * m[1][2] - m[1][0] * m[0][2];
  const T s2 = m[0][0] * m[1][3] - m[1][0] * m[0][3], s3 = m[0][1] * m[1][2] - m[1][1] * m[0][2];
  const T s4 = m[0][1] * m[1][3] - m[1][1] * m[0][3], s5 = m[0][2] * m[1][3] - m[1][2] * m[0][3];
  const T c5 = m[2][2] * m[3][3] - m[3][2] * m[2][3], c4 = m[2][1] * m[3][3] - m[3][1] * m[2][3];
  const T c3 = m[2][1] * m[3][2] - m[3][1] * m[2][2], c2 = m[2][0] * m[3][3] - m[3][0] * m[2][3];
  const T c1 = m[2][0] * m[3][2] - m[3][0] * m[2][2], c0 = m[2][0] * m[3][1] - m[3][0] * m[2][1];
  const T inv = 1.0 / (s0 * c5 - s1 * c4 + s2 * c3 + s3 * c2 - s4 * c1 + s5 * c0);
  out[0][0] = (m[1][1] * c5 - m[1][2] * c4 + m[1][3] * c3) * inv;
  out[0][1] = (-m[0][1] * c5 + m[0][2] * c4 - m[0][3] * c3) * inv;
  out[0][2] = (m[3][1] * s5 - m[3][2] * s4 + m[3][3] * s3) * inv;
  out[0][3] = (-m[2][1] * s5 + m[2][2] * s4 - m[2][3] * s3) * inv;
  out[1][0] = (-m[1][0] * c5 + m[1][2] * c2 - m[1][3] * c1) * inv;
  out[1][1] = (m[0][0] * c5 - m[0][2] * c2 + m[0][3] * c1) * inv;
  out[1][2] = (-m[3][0] * s5 + m[3][2] * s2 - m[3][3] * s1) * inv;
  out[1][3] = (m[2][0] * s5 - m[2][2] * s2 + m[2][3] * s1) * inv;
  out[2][0] = (m[1][0] * c4 - m[1][1] * c2 + m[1][3] * c0) * inv;
  out[2][1] = (-m[0][0] * c4 + m[0][1] * c2 - m[0][3] * c0) * inv;
  out[2][2] = (m[3][0] * s4 - m[3][1] * s2 + m[3][3] * s0) * inv;
  out[2][3] = (-m[2][0] * s4 + m[2][1] * s2 - m[2][3] * s0) * inv;
  out[3][0] = (-m[1][0] * c3 + m[1][1] * c1 - m[1][2] * c0) * inv;
  out[3][1] = (m[0][0] * c3 - m[0][1] * c1 + m[0][2] * c0) * inv;
  out[3][2] = (-m[3][0] * s3 + m[3][1] * s1 - m[3][2] * s0) * inv;
  out[3][3] = (m[2][0] * s3 - m[2][1] * s1 + m[2][2] * s0) * inv;
}


// u = g^{-1} p for a symmetric 4x4 metric g_{mu nu} whose spatial block gamma_ij = g_ij is invertible and
// whose g^{tt} is not 0 (the t = const slices are not null), by the 3+1 split: with the shift
// beta^i = gamma^{ij} g_tj and alpha^2 = beta^i g_ti - g_tt (= -1 / g^{tt}, the lapse squared),
//   u^t = (beta^i p_i - p_t) / alpha^2,   u^i = gamma^{ij} p_j - beta^i u^t.
// About 90 operations against cofactor_inverse4's 170 and its product with p; branch-free (double, Dual,
// Lanes). A generated metric uses it where its line element allows (codegen.py).
template <class T>
inline void split_solve4(const T g[4][4], const T p[4], T u[4]) {
  const T a = g[1][1], b = g[1][2], c = g[1][3], d = g[2][2], e = g[2][3], f = g[3][3];
  const T A = d * f - e * e, B = c * e - b * f, C = b * e - c * d;  // adjugate of gamma, symmetric
  const T D = a * f - c * c, E = b * c - a * e, F = a * d - b * b;
  const T inv = 1.0 / (a * A + b * B + c * C);
  const T s0 = g[0][1], s1 = g[0][2], s2 = g[0][3];
  const T b0 = (A * s0 + B * s1 + C * s2) * inv, b1 = (B * s0 + D * s1 + E * s2) * inv,
          b2 = (C * s0 + E * s1 + F * s2) * inv;
  const T q0 = (A * p[1] + B * p[2] + C * p[3]) * inv, q1 = (B * p[1] + D * p[2] + E * p[3]) * inv,
          q2 = (C * p[1] + E * p[2] + F * p[3]) * inv;
  const T alpha2 = b0 * s0 + b1 * s1 + b2 * s2 - g[0][0];
  const T ut = (b0 * p[1] + b1 * p[2] + b2 * p[3] - p[0]) / alpha2;
  u[0] = ut;
  u[1] = q0 - b0 * ut;
  u[2] = q1 - b1 * ut;
  u[3] = q2 - b2 * ut;
}

// out = G^{-1/2} for a symmetric positive definite 3x3 matrix G (cyclic Jacobi eigen-decomposition).
// Returns false if G is not positive definite.
inline bool sym_inv_sqrt3(const double g[3][3], double out[3][3]) {
  double a[3][3], v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) a[i][j] = g[i][j];
  for (int sweep = 0; sweep < 50; ++sweep) {
    const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    const double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
    if (off <= 1e-34 * diag) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        if (a[p][q] == 0.0) continue;
        const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
        const double t = (theta >= 0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        for (int k = 0; k < 3; ++k) {  // A <- A J
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {  // A <- J^T A
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {  // V <- V J
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
  }
  double w[3];
  for (int i = 0; i < 3; ++i) {
    if (!(a[i][i] > 0.0)) return false;
    w[i] = 1.0 / std::sqrt(a[i][i]);
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[i][j] = v[i][0] * w[0] * v[j][0] + v[i][1] * w[1] * v[j][1] + v[i][2] * w[2] * v[j][2];
  return true;
}

}  // namespace wv
