// Radii that characterise a spacetime, for rendering (capture of camera rays), for drawing (horizon,
// photon sphere or region, ergosurface, throat) and for the teaching view's labels. Radii are the
// metric's own radial coordinate (areal radius; Boyer-Lindquist r for Kerr-type metrics, whose
// Cartesian Kerr-Schild surfaces of constant r are oblate spheroids with semi-axes sqrt(r^2 + a^2) and r).
// A radius of 0 means the spacetime has no such landmark.
#pragma once

namespace wv {

struct Landmarks {
  double horizon = 0.0;        // outer event horizon
  double inner_horizon = 0.0;  // inner (Cauchy) horizon, where there is one
  // Backward camera rays moving inward through this sphere are captured (between the horizon and the
  // innermost photon orbit; must be set by every black hole, contract-tested).
  double capture = 0.0;
  double photon_sphere = 0.0;  // spherical photon orbit of a non-rotating spacetime
  // Photon region of a rotating one: equatorial prograde and retrograde circular orbits, polar orbit.
  double photon_prograde = 0.0, photon_retrograde = 0.0, photon_polar = 0.0;
  double ergosphere = 0.0;  // outer ergosurface on the equator (its profile r_E(theta) is metric-specific)
  double throat = 0.0;      // wormhole throat (areal radius)
  double mass = 0.0;        // length scale M of the strong-field region
  double spin = 0.0;        // a (a length): oblateness of the Kerr-Schild chart's constant-r surfaces
  double escape = 0.0;      // where rays escape in a spacetime that is not asymptotically flat (escape_limit)
};

}  // namespace wv
