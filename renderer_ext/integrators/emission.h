// What a path collects at the end of a segment: the radiance the sky or an emitter sends towards it, for
// emitters that ask for it shifted by the gravitational and Doppler shift g between emitter and observer
// (beaming as g^4, or the whole spectrum shifted channel by channel).
#pragma once

#include <algorithm>
#include <cmath>

#include "core/vec3.h"
#include "integrators/segment.h"
#include "scene/scene.h"
#include "spacetime/geodesic.h"

namespace wv {

template <class M>
class Emission {
 public:
  Emission(const M& m, const Scene& sc) : m_(m), sc_(sc) {}

  // Radiance emitted towards the path by what a segment reached.
  V3 emission(const SegmentEnd& e) const {
    if (e.status == kEscaped) return sc_.sky(e.sheet).radiance(e.dir);
    if (e.status != kHit) return {0, 0, 0};
    const V3 L = sc_.emitted(e.prim, e.surface, e.normal_local, -e.dir);
    const Material& m = sc_.materials[sc_.prims[e.prim].material];
    if (!m.beaming || max_component(L) <= 0.0) return L;
    const double g = shift(e, m);
    return shifted(L, g, m.colour_shift);
  }

  // Radiance L seen shifted by g: bolometric (L g^4: I_nu / nu^3 is invariant) or, with `colour`, the
  // spectrum shifted channel by channel as well.
  static V3 shifted(V3 L, double g, bool colour) {
    if (colour) return shifted_colour(L, g);
    return L * (g * g * g * g);
  }

  // Radiance seen in each channel when the source's spectrum is shifted by g: I_nu / nu^3 is invariant,
  // so I_obs(nu) = g^3 I_emit(nu / g). The emitted spectrum is read off the RGB triple as piecewise
  // exponential in frequency through the channels' frequencies (610, 550, 465 nm), continued beyond them
  // with the end segments' slopes (a Wien-like tail), so an exponential spectrum shifts exactly.
  static V3 shifted_colour(V3 L, double g) {
    if (!(g > 0.0)) return {0, 0, 0};
    const double nu[3] = {1.0 / 610.0, 1.0 / 550.0, 1.0 / 465.0};
    const double floor = 1e-6 * std::max(max_component(L), 1e-300);
    const double lg[3] = {std::log(std::max(L.x, floor)), std::log(std::max(L.y, floor)),
                          std::log(std::max(L.z, floor))};
    auto spectrum = [&](double f) {
      const int k = f < nu[1] ? 0 : 1;
      const double t = std::min(50.0, std::max(-50.0, (f - nu[k]) / (nu[k + 1] - nu[k])));
      return std::exp(lg[k] * (1.0 - t) + lg[k + 1] * t);
    };
    const double g3 = g * g * g;
    return {g3 * spectrum(nu[0] / g), g3 * spectrum(nu[1] / g), g3 * spectrum(nu[2] / g)};
  }

  // g = nu_received / nu_emitted for light from the emitter at a hit to the segment's start observer:
  // 1 / (p . u_emitter) with the backward momentum normalised to unit energy at the start.
  double shift(const SegmentEnd& e, const Material& m) const {
    if constexpr (M::kFlat) {  // static emitters; only a moving camera's segments have energy != 1
      (void)m;
      return e.energy > 0.0 ? 1.0 / e.energy : 0.0;
    } else {
      double E = e.energy;  // static emitter
      if (m.keplerian) {
        const double om = m_.keplerian_omega(e.y);
        const double v[4] = {1.0, -om * e.y[2], om * e.y[1], 0.0};  // d/dt + Omega d/dphi
        double n2 = 0.0;
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b) n2 += e.frame.g[a][b] * v[a] * v[b];
        if (n2 < 0.0) {  // timelike: a circular orbit exists here
          const double s = 1.0 / std::sqrt(-n2);
          E = 0.0;
          for (int a = 0; a < 4; ++a) E += e.y[4 + a] * v[a] * s;
        }
      }
      return E > 0.0 ? 1.0 / E : 0.0;
    }
  }

 private:
  const M& m_;
  const Scene& sc_;
};

}  // namespace wv
