// Bracketed root finding for crossings located on a step's dense output (horizon, escape sphere,
// surfaces): the Illinois variant of regula falsi, superlinear on smooth functions and never leaving
// its bracket, so it needs ~6-10 evaluations where bisection needs 45-60.
#pragma once

#include <cmath>

namespace wv {

// f changes sign on [lo, hi] (f(lo) = flo, f(hi) = fhi, opposite signs). Returns a point t on the hi
// side of the crossing (sign of f(t) that of fhi, or f(t) = 0) with |f(t)| <= ftol or within xtol of the
// crossing.
template <class F>
double crossing(const F& f, double lo, double flo, double hi, double fhi, double xtol, double ftol) {
  int side = 0;  // which end moved last (-1 lo, +1 hi), for the Illinois halving
  for (int it = 0; it < 100 && hi - lo > xtol; ++it) {
    double t = (lo * fhi - hi * flo) / (fhi - flo);
    if (!(t > lo && t < hi)) t = 0.5 * (lo + hi);  // rounding at a flat end: bisect
    const double ft = f(t);
    if (ft == 0.0) return t;
    if ((ft < 0.0) == (fhi < 0.0)) {
      hi = t;
      fhi = ft;
      if (std::fabs(ft) <= ftol) return hi;
      if (side == 1) flo *= 0.5;
      side = 1;
    } else {
      lo = t;
      flo = ft;
      if (side == -1) fhi *= 0.5;
      side = -1;
    }
  }
  return hi;
}

}  // namespace wv
