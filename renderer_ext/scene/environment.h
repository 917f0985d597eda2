// Radiance arriving from infinity along a direction (the sky an escaped ray sees): a uniform colour,
// an equirectangular image, a procedural star field and marked discs ("spots").
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/rng.h"
#include "core/vec3.h"
#include "scene/texture.h"

namespace wv {

struct Spot {
  V3 direction;       // unit
  double cos_radius;  // cos of the angular radius
  V3 color;
};

struct StarField {
  bool enabled = false;
  double density = 0.0;     // mean stars per steradian
  double brightness = 1.0;  // peak radiance of the brightest stars
  double size = 0.002;      // angular radius (rad) of the Gaussian star profile
  uint64_t seed = 0;
  int cells = 1;            // cells per cube face edge (each holds at most one star)
  double fill = 0.0;        // probability a cell holds a star

  void setup() {
    if (density <= 0.0) { enabled = false; return; }
    const double per_face = density * 4.0 * M_PI / 6.0;
    cells = std::max(1, int(std::ceil(std::sqrt(per_face / 0.25))));
    fill = std::min(1.0, per_face / (double(cells) * cells));
    enabled = true;
  }

  // Star of cell (face, i, j): direction, colour and peak radiance; false if the cell is empty.
  bool star(int face, long i, long j, V3& dir, V3& col) const {
    const uint64_t key = mix64(seed ^ mix64((uint64_t(face) << 48) ^ (uint64_t(i) << 24) ^ uint64_t(j)));
    Rng rng(key, 0, 0);
    if (rng.uniform() >= fill) return false;
    const double a = -1.0 + 2.0 * (i + rng.uniform()) / cells, b = -1.0 + 2.0 * (j + rng.uniform()) / cells;
    dir = normalize(face_point(face, a, b));
    // Brightness: a steep power law (most stars faint); colour from blue-white to orange.
    const double m = std::pow(rng.uniform(), 4.0);
    const double t = rng.uniform();
    const V3 tint = V3{0.75, 0.85, 1.0} * (1.0 - t) + V3{1.0, 0.8, 0.55} * t;
    col = tint * (brightness * (0.05 + 0.95 * m));
    return true;
  }

  static V3 face_point(int face, double a, double b) {
    switch (face) {
      case 0: return {1, a, b};
      case 1: return {-1, a, b};
      case 2: return {a, 1, b};
      case 3: return {a, -1, b};
      case 4: return {a, b, 1};
      default: return {a, b, -1};
    }
  }

  V3 radiance(V3 d) const {
    const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    int face;
    double a, b;
    if (ax >= ay && ax >= az) { face = d.x > 0 ? 0 : 1; a = d.y / ax; b = d.z / ax; }
    else if (ay >= az) { face = d.y > 0 ? 2 : 3; a = d.x / ay; b = d.z / ay; }
    else { face = d.z > 0 ? 4 : 5; a = d.x / az; b = d.y / az; }
    const long ci = std::min<long>(cells - 1, long((a + 1.0) * 0.5 * cells));
    const long cj = std::min<long>(cells - 1, long((b + 1.0) * 0.5 * cells));
    V3 sum{0, 0, 0};
    const double inv_s2 = 1.0 / (size * size);
    for (long i = ci - 1; i <= ci + 1; ++i)
      for (long j = cj - 1; j <= cj + 1; ++j) {
        if (i < 0 || j < 0 || i >= cells || j >= cells) continue;
        V3 sd, col;
        if (!star(face, i, j, sd, col)) continue;
        const double c = dot(sd, d);
        if (c <= 0.0) continue;
        const V3 diff = d - sd;
        const double ang2 = dot(diff, diff);  // ~ angle^2 for small angles
        if (ang2 > 9.0 * size * size) continue;
        sum += col * std::exp(-ang2 * inv_s2);
      }
    return sum;
  }
};

struct Environment {
  V3 color{0, 0, 0};
  bool has_image = false;
  Texture image;  // equirectangular, +z up
  StarField stars;
  std::vector<Spot> spots;

  V3 radiance(V3 d) const {
    V3 L = color;
    if (has_image) {
      double phi = std::atan2(d.y, d.x);
      const double u = phi / (2.0 * M_PI) + 0.5;
      const double v = 1.0 - std::acos(std::max(-1.0, std::min(1.0, d.z))) / M_PI;
      L += image.image(u, v);
    }
    if (stars.enabled) L += stars.radiance(d);
    for (const Spot& s : spots)
      if (dot(d, s.direction) >= s.cos_radius) L += s.color;
    return L;
  }
};

}  // namespace wv
