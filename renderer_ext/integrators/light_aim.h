// Aiming light samples through a lens: a pilot geodesic shot from a surface point towards a light's
// centre shows where bending takes it; the light's proxy is then shifted by the opposite offset, so
// directions sampled from it land on the light instead of missing it (to first order in the bending).
//
// The pilot is deterministic (no random numbers) and is the same for the light strategy's sample and
// for the pdf evaluated at a BSDF-sampled direction at that vertex, so the shifted proxy is a valid
// density over directions and the estimator stays unbiased; the pilot only decides how good it is.
#pragma once

#include <cmath>

#include "core/root.h"
#include "core/vec3.h"

namespace wv {

// Surface set for integrate_ray: the first crossing of the plane through `centre` with normal `normal`
// on sheet `sheet`.
template <class M>
struct PlaneTarget {
  static constexpr bool kActive = true;
  static constexpr bool kDenseEnd = true;  // a pilot only needs where it lands
  const M& m;
  V3 centre, normal;
  int sheet;

  template <class S>
  bool find(const S& st, const double* y, const double* ynew, double h, int ray_sheet, double& theta, int& prim) const {
    double a[3], b[3], ys[8], q[3];
    if (m.chart_to_user(y, ray_sheet, a) != sheet || m.chart_to_user(ynew, ray_sheet, b) != sheet) return false;
    const double fa = dot(V3(a) - centre, normal), fb = dot(V3(b) - centre, normal);
    if ((fa < 0.0) == (fb < 0.0)) return false;
    auto f = [&](double t) {
      st.dense(y, ynew, h, t, ys);
      m.chart_to_user(ys, ray_sheet, q);
      return dot(V3(q) - centre, normal);
    };
    theta = crossing(f, 0.0, fa, 1.0, fb, 1e-12, 1e-9 * (1.0 + length(centre)));
    prim = -1;
    return true;
  }
};

}  // namespace wv
