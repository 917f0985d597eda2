// The chart of a wormhole whose two sheets are exchanged by an inversion (the Ellis file, and wormholes
// written as their line element in coordinates = "wormhole"): with l = (rho - c^2 / rho) / 2, rho = |x|,
// the inversion x -> c^2 x / rho^2 is l -> -l, an isometry when the metric is even in l. A ray is kept at
// rho >= c with a sheet flag.
#pragma once

namespace wv {

// Moves state y = (x, p) that has stepped inside rho < c to the other sheet's chart (x' = c^2 x / rho^2, its
// covariant momentum p' = (rho^2 / c^2)(1 - 2 x^ x^T) p) and flips `sheet`; false (nothing changed) outside.
inline bool invert_through_throat(double* y, double c2, int& sheet) {
  const double rho2 = y[1] * y[1] + y[2] * y[2] + y[3] * y[3];
  if (rho2 >= c2) return false;
  const double xp = (y[1] * y[5] + y[2] * y[6] + y[3] * y[7]) / rho2;
  const double k = rho2 / c2;
  for (int i = 1; i < 4; ++i) {
    y[4 + i] = k * (y[4 + i] - 2.0 * xp * y[i]);
    y[i] *= c2 / rho2;
  }
  sheet = -sheet;
  return true;
}

}  // namespace wv
