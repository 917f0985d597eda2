// The camera's light connection: light samples drawn for the camera itself, in the pixels where a light's lensed
// image is small (a sun far away, a lamp's thin arc against a hole or a throat).
//
// A camera ray finds a light it sees directly only by landing on its image, so a pixel that holds a sub-pixel sun
// of strength 4000 is the noisiest of a picture whatever the light connection does at the surfaces. In a static
// spherical metric seen by a static camera the exact lens map (lens_connection.h) gives the images of a light
// point from the camera, so the camera can draw a point on a light, map it through the lens map into the image
// and trace the ray of each image that lands in the pixel being sampled: a second strategy for the pixel's
// directly seen emission, combined with the camera ray by the balance heuristic. In image coordinates (pixel
// units, a pixel of area 1, its camera samples uniform in it) the light strategy's density at image point x is
//
//   rho(x) = P(light) (1 / area) |dA_B / dOmega| dOmega / dx,
//
// the lens map's area Jacobian (lens_area_jacobian) times the pinhole's solid angle per unit of image area, and
// the balance heuristic weighs a camera ray that hits a light at B by 1 / (1 + rho), rho that of the image of B it
// is, and a light sample whose image lands in the pixel and whose ray hits that light by rho_c / (rho_s (1 +
// rho_c)) (shot_weight): rho_s its own density, rho_c the camera ray's rho for the ray it traced, so the weights
// add up to one for every camera direction whatever the integrator's error; where the light strategy cannot reach
// (an image order the pixel does not solve for, the far half of a sphere) rho is 0 and the camera ray counts alone.
//
// The pixels it runs in, and the lights it picks there, come from the scene alone: kGrid^2 points on each light
// (by area, as sample_light_point draws them from the camera) are mapped into the image, and a pixel where a
// light's points land with probability >= kMinShare per light sample gets the strategy, choosing among the lights
// in proportion to how many of their points land in it, and drawing the point within the box of sampling numbers
// whose grid points landed there (a grid cell wider on every side). A lamp seen large is left to the camera rays,
// which see its inside without noise, and so is a pixel inside a light's image (it and its neighbours all hold
// some of the light's points). Every window and tile of an image agrees on it.
//
// The stars of a star field (scene/environment.h) are lights at infinity of the same kind: a pixel that holds
// an image of a star's centre smaller than the pixel also draws a star (in proportion to their light) and a
// direction in its Gaussian profile, whose images are those of a point far out along it (kSkyRadius), with
// dOmega_sky / dOmega = |dA_B / dOmega| / R_B^2; the sample counts if its ray escapes to that sky. Its density on
// the sky is the mixture of the pixel's stars' profiles, which a camera ray that escapes there is weighed by, at
// the sky direction the lens map gives for it (star_rho). A pixel solves for the image orders whose images fell in it at the
// start (up to all four: a star's images of order 2 and 3 crowd at a throat's rim, sub-pixel and bright).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/linalg.h"
#include "core/parallel.h"
#include "core/vec3.h"
#include "integrators/camera.h"
#include "integrators/lens_connection.h"
#include "integrators/render_types.h"
#include "scene/light.h"
#include "scene/scene.h"
#include "spacetime/lens_map.h"

namespace wv {

// One image of a light point (or of a star's sky direction) that a sample drew for a pixel: the camera ray's local
// direction, the light prim it must hit (or the sky of `sheet` it must escape to), and the strategy's density rho
// of that direction (CameraConnection::shot_weight).
struct CameraShot {
  V3 w;
  V3 target;  // (a light's) the point drawn on it, user frame
  int prim = -1;
  double rho = 0.0;
  bool sky = false;  // a star's, of the sky of `sheet`
  int sheet = 1;
};

template <class M>
class CameraConnection {
 public:
  static constexpr int kGrid = 32;              // points per side on each light for the pixels' shares
  // Image orders drawn: all the lens map's (a light's or a star's images of order 2 and 3 crowd at a throat's rim
  // or a hole's shadow, sub-pixel and bright; in fig13 at 48 x 36 the sun's held most of the variance left with
  // orders 0 and 1).
  static constexpr int kOrders = LensImages::kMax;
  static constexpr double kMinShare = 1.0 / 32;  // a pixel's least share of a light sample to get the strategy

  // Active (o.camera_light_samples) where the lens connection is the light strategy of a static spherical metric,
  // the camera is static, sees no shift of its own, samples its pixels uniformly (the box filter of the pixel
  // itself) and lies where the lens map applies; `on`: the caller's other conditions (not a guide's training).
  CameraConnection(const Scene& sc, const RenderOptions& o, const CameraRays<M>& cam, const LensConnection<M>& lens,
                   bool on)
      : sc_(sc), cam_(cam), lens_(lens), threads_(o.threads) {
    if constexpr (M::kStaticSpherical) {
      const V3 pos = sc.camera.position;
      const SphericalLens& sl = lens.lens();
      if (!on || !o.camera_light_samples || !o.light_sampling || o.light_connection != kLensConnection ||
          !cam.static_observer() || sc.camera.shift != kShiftNone || o.filter != kBoxFilter ||
          !(o.filter_radius == 0.0 || o.filter_radius == 0.5) || !(sl.u_inner > 0.0) ||
          !(length(pos) * sl.u_inner > 1.05))
        return;
      v_.pos = pos;
      v_.sheet = sc.camera.sheet;
      v_.to_local = cam.to_local();
      v_.radial_local = normalize(v_.to_local(normalize(pos)));
      if (!invert3(v_.to_local.m, from_local_.m)) return;
      const double aspect = double(sc.camera.width) / sc.camera.height;
      const double t = std::tan(0.5 * sc.camera.fov * M_PI / 180.0);
      pixel_solid_ = (2.0 * t * aspect / sc.camera.width) * (2.0 * t / sc.camera.height);
      if (!sc.lights.empty()) build_shares();
      build_stars();
    }
  }

  // Whether image pixel (px, py) gets the strategy (a light's, a star's or both).
  bool applies(int px, int py) const { return light_slot(px, py) >= 0 || star_count(px, py) > 0; }

  // Whether it draws a light, and whether it draws a star.
  bool draws_lights(int px, int py) const { return light_slot(px, py) >= 0; }
  bool draws_stars(int px, int py) const { return star_count(px, py) > 0; }

  // rho of the camera ray of pixel (px, py) along local direction d that escaped to the sky of `sheet` (0 where no
  // star of the pixel's is drawn there). The sky direction is the lens map's for d, evaluated forward, not the
  // traced ray's: at a throat's rim or a hole's shadow an image of order 2 or 3 bends the integrator's error by
  // e^(2 pi) a winding, and both strategies must weigh the same camera direction alike (a star sample counts
  // wherever on that sky its ray escapes).
  double star_rho(int px, int py, V3 d, int sheet) const {
    const size_t pix = size_t(py) * size_t(sc_.camera.width) + size_t(px);
    if (star_off_.empty() || star_off_[pix] == star_off_[pix + 1]) return 0.0;
    const double cpsi = std::clamp(dot(d, v_.radial_local), -1.0, 1.0), psi = std::acos(cpsi);
    const V3 tl = d - v_.radial_local * cpsi;
    if (!(length(tl) > 1e-12)) return 0.0;
    const V3 xa = normalize(v_.pos);
    V3 tu = from_local_(tl);
    tu = normalize(tu - xa * dot(tu, xa));  // the ray's plane in the user frame: its tangent at A
    const LensMap map(lens_.lens(), 1.0 / length(v_.pos), 1.0 / kSkyRadius, sheet == v_.sheet);
    const LensRay r = map.at_psi(psi);
    if (!r.ok || !(r.phi < M_PI * pixel_orders(px, py)) || !std::isfinite(r.dphi_dpsi)) return 0.0;
    const double q = star_mixture(pix, sheet, xa * std::cos(r.phi) + tu * std::sin(r.phi));
    if (!(q > 0.0)) return 0.0;
    const double jac = std::fabs(std::sin(r.phi) * r.dphi_dpsi) / std::sin(psi);  // dOmega_sky / dOmega
    return per_pixel(d, q * jac);
  }

  // A star sample for pixel (px, py): u0 picks the star, u1, u2 a direction in its profile; the images of that
  // direction that land in the pixel are written to `out`. Returns how many.
  int sample_star(int px, int py, double u0, double u1, double u2, CameraShot* out) const {
    const size_t pix = size_t(py) * size_t(sc_.camera.width) + size_t(px);
    if (star_off_.empty()) return 0;
    const size_t b = star_off_[pix], e = star_off_[pix + 1];
    if (b == e) return 0;
    size_t k = e - 1;
    double acc = 0.0;
    for (size_t i = b; i < e; ++i) {
      acc += star_list_[i].p;
      if (u0 < acc) {
        k = i;
        break;
      }
    }
    const SkyStar& st = stars_[size_t(star_list_[k].star)];
    // The profile exp(-|v|^2 / s^2) on the tangent plane at the star, cut at |v| = kStarCut s, by inversion.
    const double s = sc_.sky(st.sheet).stars.size;
    const double r = s * std::sqrt(-std::log1p(-u1 * (1.0 - std::exp(-kStarCut * kStarCut))));
    V3 t, bt;
    basis_around(st.dir, t, bt);
    const V3 n = normalize(st.dir + t * (r * std::cos(kTwoPi * u2)) + bt * (r * std::sin(kTwoPi * u2)));
    const double q = star_mixture(pix, st.sheet, n);
    if (!(q > 0.0)) return 0;
    const LensImageRays rays = lens_image_rays(lens_.lens(), v_, sky_point(n, st.sheet), pixel_orders(px, py));
    int m = 0;
    for (int i = 0; i < rays.n; ++i) {
      double x, y;
      if (!cam_.pixel_of(rays.ray[i].w, x, y) || int(std::floor(x)) != px || int(std::floor(y)) != py) continue;
      const double rho = sky_density(rays, rays.ray[i], q);
      if (!(rho > 0.0)) continue;
      CameraShot& c = out[m++];
      c.w = rays.ray[i].w;
      c.prim = -1;
      c.rho = rho;
      c.sky = true;
      c.sheet = st.sheet;
    }
    return m;
  }

  // What a sample's traced ray e brings to pixel (px, py), as a share of the emission it found: shot s drew its
  // direction with density s.rho; the weight is the camera ray's own rho for that direction, from what the ray
  // met (rho, star_rho), so the two strategies' weights add up to one for every direction even where the traced
  // ray strays from the lens map's (the integrator's error, amplified e^(2 pi) a winding at the higher orders):
  // rho_c / (s.rho (1 + rho_c)). 0 unless the ray met what it was drawn for: that light at the point drawn
  // (hit_aim: the image of a sphere's point round the hole, or one grazing its limb, reaches the point from a side
  // the sphere itself hides, and the ray first hits another of its points, whose own draws already bring that
  // direction: counted for both, a sphere lamp seen through a hole came out 10 % too bright), or that sky anywhere
  // on it.
  double shot_weight(int px, int py, const CameraShot& s, const SegmentEnd& e) const {
    double rc = 0.0;
    if (s.sky && e.status == kEscaped && e.sheet == s.sheet) rc = star_rho(px, py, s.w, e.sheet);
    if (!s.sky && e.status == kHit && e.prim == s.prim && hit_aim(e.pos, s.target))
      rc = rho(px, py, s.w, e.prim, e.pos);
    return rc > 0.0 ? rc / (s.rho * (1.0 + rc)) : 0.0;
  }

  // rho of the camera ray of pixel (px, py) along local direction d, which first hits light prim p at user-frame
  // point x (0 where the light strategy never draws it).
  double rho(int px, int py, V3 d, int p, V3 x) const {
    const int s = light_slot(px, py);
    const auto it = std::find(sc_.lights.begin(), sc_.lights.end(), p);
    if (s < 0 || it == sc_.lights.end()) return 0.0;
    const size_t k = size_t(s) * sc_.lights.size() + size_t(it - sc_.lights.begin());
    const double pl = share_[k];
    if (!(pl > 0.0)) return 0.0;
    LightPoint lp;
    double u1, u2;
    if (!light_point_at(sc_, p, v_.pos, x, lp) || !light_point_uv(sc_, p, v_.pos, x, u1, u2)) return 0.0;
    const UvBox& bx = box_[k];
    if (!(u1 >= bx.lo1 && u1 <= bx.hi1 && u2 >= bx.lo2 && u2 <= bx.hi2)) return 0.0;
    lp.area *= bx.area();  // the part of the light the pixel's samples draw from
    const LensImageRays rays = lens_image_rays(lens_.lens(), v_, lens_light(p, lp), pixel_orders(px, py));
    int best = -1;  // the image the ray is: the nearest within the match (images crowd at a hole's shadow)
    double best_cos = 1.0 - kLensMatchCos;
    for (int k = 0; k < rays.n; ++k) {
      const double c = dot(rays.ray[k].w, d);
      if (c > best_cos) {
        best_cos = c;
        best = k;
      }
    }
    return best >= 0 ? density(rays, rays.ray[best], lp, pl) : 0.0;
  }

  // A light sample for pixel (px, py): u0 picks the light, u1, u2 the point on it; the images of the point that
  // land in the pixel (at most LensImages::kMax) are written to `out`. Returns how many.
  int sample(int px, int py, double u0, double u1, double u2, CameraShot* out) const {
    const int s = light_slot(px, py);
    if (s < 0) return 0;
    const int nl = int(sc_.lights.size());
    int li = nl - 1;
    double acc = 0.0;
    for (int i = 0; i < nl; ++i) {
      acc += share_[size_t(s) * nl + i];
      if (u0 < acc) {
        li = i;
        break;
      }
    }
    const double pl = share_[size_t(s) * nl + li];
    if (!(pl > 0.0)) return 0;
    const int p = sc_.lights[li];
    const UvBox& bx = box_[size_t(s) * nl + li];  // drawn within the part of the light the pixel sees
    LightPoint lp;
    if (!sample_light_point(sc_, p, v_.pos, bx.lo1 + u1 * (bx.hi1 - bx.lo1), bx.lo2 + u2 * (bx.hi2 - bx.lo2), lp))
      return 0;
    lp.area *= bx.area();
    const LensImageRays rays = lens_image_rays(lens_.lens(), v_, lens_light(p, lp), pixel_orders(px, py));
    int n = 0;
    for (int k = 0; k < rays.n; ++k) {
      double x, y;
      if (!cam_.pixel_of(rays.ray[k].w, x, y) || int(std::floor(x)) != px || int(std::floor(y)) != py) continue;
      const double rho = density(rays, rays.ray[k], lp, pl);
      if (!(rho > 0.0)) continue;
      out[n++] = {rays.ray[k].w, lp.pos, p, rho};
    }
    return n;
  }

 private:
  // rho of image ray ir of light point lp, the light chosen with probability pl: 0 where the Jacobian is not
  // finite (a ray grazing the light).
  double density(const LensImageRays& rays, const LensImageRay& ir, const LightPoint& lp, double pl) const {
    if (!std::isfinite(ir.r.dphi_dpsi)) return 0.0;
    const double cos_n = std::fabs(dot(ir.t_arr, lp.normal));
    if (!(cos_n > 0.0)) return 0.0;
    return per_pixel(ir.w, pl / lp.area * lens_area_jacobian(rays, ir, cos_n));  // |dA_B / dOmega|
  }

  // The image orders a pixel's samples solve for: up to the highest whose image of a light's grid point or of a
  // star's centre fell in it at the start (most pixels need order 0 alone; each order is a root of the lens map).
  // Both strategies of a pixel use the same, so its weights stay consistent.
  int pixel_orders(int px, int py) const {
    return orders_.empty() ? 0 : orders_[size_t(py) * size_t(sc_.camera.width) + size_t(px)];
  }
  void note_order(size_t pix, int k) {
    if (orders_.empty()) orders_.assign(size_t(sc_.camera.width) * sc_.camera.height, 0);
    orders_[pix] = uint8_t(std::max<int>(orders_[pix], k + 1));
  }

  int light_slot(int px, int py) const {
    return slot_.empty() ? -1 : slot_[size_t(py) * size_t(sc_.camera.width) + size_t(px)];
  }
  size_t star_count(int px, int py) const {
    if (star_off_.empty()) return 0;
    const size_t pix = size_t(py) * size_t(sc_.camera.width) + size_t(px);
    return star_off_[pix + 1] - star_off_[pix];
  }

  // A direction on the sky of `sheet` as a far point for the lens map (its images are the direction's to ~1e-8).
  static LensLight sky_point(V3 n, int sheet) { return LensLight{n * kSkyRadius, n, 0.0, sheet, true}; }

  // rho of image ray ir of a sky direction whose density on the sky (per steradian) is q: q |dOmega_sky /
  // dOmega| dOmega / dx.
  double sky_density(const LensImageRays& rays, const LensImageRay& ir, double q) const {
    if (!std::isfinite(ir.r.dphi_dpsi)) return 0.0;
    const double cos_r = std::fabs(dot(ir.t_arr, rays.xb));
    if (!(cos_r > 0.0)) return 0.0;
    const double jac = lens_area_jacobian(rays, ir, cos_r) / (rays.RB * rays.RB);  // dOmega_sky / dOmega
    return per_pixel(ir.w, q * jac);
  }

  // rho from a density per steradian at the camera along local direction w: times the pinhole's solid angle per
  // unit of image (dOmega / dx = f^3 pixel_solid_, f the cosine from the forward axis); 0 unless finite and > 0.
  double per_pixel(V3 w, double per_sr) const {
    const double f = dot(w, cam_.forward());
    const double rho = per_sr * f * f * f * pixel_solid_;
    return rho > 0.0 && std::isfinite(rho) ? rho : 0.0;
  }

  // The density on the sky (per steradian) with which pixel pix's star samples draw direction n of `sheet`: the
  // mixture of its stars' profiles, each chosen with its probability there.
  double star_mixture(size_t pix, int sheet, V3 n) const {
    double q = 0.0;
    for (size_t i = star_off_[pix]; i < star_off_[pix + 1]; ++i) {
      const SkyStar& st = stars_[size_t(star_list_[i].star)];
      if (st.sheet != sheet) continue;
      const double c = dot(n, st.dir);
      if (!(c > 0.0)) continue;
      const V3 v = n / c - st.dir;  // on the tangent plane
      const double s = sc_.sky(sheet).stars.size, v2 = dot(v, v);
      if (v2 > kStarCut * kStarCut * s * s) continue;
      // The plane's density, over c^3 (the plane's area per steradian, at angle theta: 1 / cos^3)
      q += star_list_[i].p * std::exp(-v2 / (s * s)) /
           (M_PI * s * s * (1.0 - std::exp(-kStarCut * kStarCut)) * c * c * c);
    }
    return q;
  }

  LensLight lens_light(int p, const LightPoint& lp) const {
    return LensLight{lp.pos, lp.normal, lp.area, sc_.prims[p].sheet, true};
  }

  // Each light's kGrid^2 points mapped into the image: a pixel's share of light l is the fraction of l's points
  // (images of every order the strategy draws) that land in it; pixels whose share of some light reaches
  // kMinShare get a slot, holding the lights' probabilities there (in proportion to their shares).
  void build_shares() {
    const int W = sc_.camera.width, H = sc_.camera.height, nl = int(sc_.lights.size());
    // Every grid point's images in the image, once: (light, i, j, pixel).
    struct Landing {
      int li, i, j;
      size_t pix;
    };
    std::vector<Landing> landed;
    std::vector<std::vector<float>> count{size_t(nl)};
    for (int li = 0; li < nl; ++li) {
      const int p = sc_.lights[li];
      for (int i = 0; i < kGrid; ++i)
        for (int j = 0; j < kGrid; ++j) {
          LightPoint lp;
          if (!sample_light_point(sc_, p, v_.pos, (i + 0.5) / kGrid, (j + 0.5) / kGrid, lp)) continue;
          const LensImageRays rays = lens_image_rays(lens_.lens(), v_, lens_light(p, lp), kOrders);
          for (int k = 0; k < rays.n; ++k) {
            double x, y;
            if (!cam_.pixel_of(rays.ray[k].w, x, y)) continue;
            const double fx = std::floor(x), fy = std::floor(y);
            if (!(fx >= 0 && fy >= 0 && fx < W && fy < H)) continue;
            const size_t pix = size_t(fy) * W + size_t(fx);
            if (count[size_t(li)].empty()) count[size_t(li)].assign(size_t(W) * H, 0.0f);
            count[size_t(li)][pix] += 1.0f;
            note_order(pix, k);
            landed.push_back({li, i, j, pix});
          }
        }
    }
    const double need = kMinShare * kGrid * kGrid;
    // A pixel inside a light's image (it and its neighbours in the frame all hold some of its points) is left to
    // the camera rays, which see the light there without noise: in fig07 at 48 x 36, where the lamp's image is
    // ~30 pixels, its inner pixels drawing light samples doubled the room's error. (Its edge pixels keep them: a
    // pixel the image covers but for a sliver is no less noisy for the camera rays when the light is a sun; in
    // fig13 leaving the pixels that hold the sun's points in all four quarters to the camera rays tripled the
    // error.)
    auto inside = [&](int li, size_t pix) {
      const std::vector<float>& c = count[size_t(li)];
      const int x = int(pix % size_t(W)), y = int(pix / size_t(W));
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx >= 0 && yy >= 0 && xx < W && yy < H && !(c[size_t(yy) * W + size_t(xx)] > 0.0f)) return false;
        }
      return true;
    };
    std::vector<int> slot(size_t(W) * H, -1);
    std::vector<double> kept(static_cast<size_t>(nl));
    bool any = false;
    for (size_t pix = 0; pix < slot.size(); ++pix) {
      double sum = 0.0, most = 0.0;
      for (int li = 0; li < nl; ++li) {
        kept[size_t(li)] = count[size_t(li)].empty() || inside(li, pix) ? 0.0 : count[size_t(li)][pix];
        sum += kept[size_t(li)];
        most = std::max(most, kept[size_t(li)]);
      }
      if (!(most >= need)) continue;
      slot[pix] = int(share_.size() / size_t(nl));
      for (int li = 0; li < nl; ++li) share_.push_back(kept[size_t(li)] / sum);
      any = true;
    }
    if (!any) return;
    slot_ = std::move(slot);
    // Each slot's box of the lights' sampling numbers whose grid points landed in its pixel, a grid cell wider
    // on every side: its samples draw there alone (a light's thin arc spread over a dozen pixels would send
    // each pixel's samples elsewhere eleven times in twelve).
    std::vector<std::array<int, 4>> cells(share_.size(), {kGrid, -1, kGrid, -1});
    for (const Landing& l : landed) {
      const int sl = slot_[l.pix];
      if (sl < 0) continue;
      auto& c = cells[size_t(sl) * nl + l.li];
      c = {std::min(c[0], l.i), std::max(c[1], l.i), std::min(c[2], l.j), std::max(c[3], l.j)};
    }
    box_.resize(cells.size());
    for (size_t k = 0; k < cells.size(); ++k) {
      const auto& c = cells[k];
      if (c[1] < 0) continue;  // (no point of that light there: its share is 0)
      box_[k] = {std::max(0, c[0] - 1) / double(kGrid), std::min(kGrid, c[1] + 2) / double(kGrid),
                 std::max(0, c[2] - 1) / double(kGrid), std::min(kGrid, c[3] + 2) / double(kGrid)};
    }
  }

  // The stars of the skies (StarField) whose images from the camera are smaller than their pixel, each pixel's
  // list of them with their probabilities there (in proportion to their light): every image of each star's
  // centre, of the orders the lens connection draws, with dOmega_sky / dOmega from the lens map.
  void build_stars() {
    const int W = sc_.camera.width, H = sc_.camera.height;
    struct Entry {
      size_t pix;
      int star;
      double flux;
    };
    std::vector<Entry> entries;
    const SphericalLens& sl = lens_.lens();
    for (int sheet : {1, -1}) {
      if (sheet != sc_.camera.sheet && !sl.throat) continue;
      const StarField& sf = sc_.sky(sheet).stars;
      if (!sf.enabled) continue;
      const double s = sf.size;
      // The stars bright enough to matter (a star's noise goes with its light squared: those below kStarBright of
      // the brightest hold ~3 % of a field's), then their images in parallel (~20 us each in Ellis), kept in order.
      struct Cand {
        V3 dir;
        double flux;
        int n = 0;
        double px[kOrders] = {};
        int order[kOrders] = {};
      };
      std::vector<Cand> cand;
      for (int face = 0; face < 6; ++face)
        for (long i = 0; i < sf.cells; ++i)
          for (long j = 0; j < sf.cells; ++j) {
            V3 dir, col;
            if (!sf.star(face, i, j, dir, col)) continue;
            const double flux = (col.x + col.y + col.z) / 3.0;
            if (flux >= kStarBright * sf.brightness) cand.push_back({dir, flux});
          }
      constexpr size_t kChunk = 64;
      parallel_for((cand.size() + kChunk - 1) / kChunk, threads_, 1, [&](size_t c) {
        for (size_t q = c * kChunk; q < std::min(cand.size(), (c + 1) * kChunk); ++q) {
          Cand& cd = cand[q];
          const LensImageRays rays = lens_image_rays(sl, v_, sky_point(cd.dir, sheet), kOrders);
          for (int k = 0; k < rays.n; ++k) {
            double x, y;
            if (!cam_.pixel_of(rays.ray[k].w, x, y)) continue;
            const double fx = std::floor(x), fy = std::floor(y);
            if (!(fx >= 0 && fy >= 0 && fx < W && fy < H)) continue;
            const double jac = sky_density(rays, rays.ray[k], 1.0);  // dOmega_sky / dx
            // The image's area, kStarCut sizes round, in pixels: below one, a camera ray sees it by chance.
            if (!(jac > 0.0) || !(M_PI * kStarCut * kStarCut * s * s / jac < 1.0)) continue;
            cd.px[cd.n] = fy * W + fx;
            cd.order[cd.n++] = k;
          }
        }
      });
      for (const Cand& cd : cand) {
        if (cd.n == 0) continue;
        const int star = int(stars_.size());
        stars_.push_back({cd.dir, sheet});
        for (int k = 0; k < cd.n; ++k) {
          entries.push_back({size_t(cd.px[k]), star, cd.flux});
          note_order(size_t(cd.px[k]), cd.order[k]);
        }
      }
    }
    if (entries.empty()) return;
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
      return a.pix != b.pix ? a.pix < b.pix : a.star < b.star;
    });
    star_off_.assign(size_t(W) * H + 1, 0);
    for (size_t k = 0; k < entries.size();) {
      size_t e = k;
      double sum = 0.0;
      while (e < entries.size() && entries[e].pix == entries[k].pix) sum += entries[e++].flux;
      for (size_t i = k; i < e; ++i)
        if (i == k || entries[i].star != entries[i - 1].star)  // (two images of one star in a pixel: once)
          star_list_.push_back({entries[i].star, entries[i].flux / sum});
        else
          star_list_.back().p += entries[i].flux / sum;
      star_off_[entries[k].pix + 1] = star_list_.size();
      k = e;
    }
    for (size_t p = 1; p < star_off_.size(); ++p) star_off_[p] = std::max(star_off_[p], star_off_[p - 1]);
  }

  static constexpr double kSkyRadius = 1e8;  // where a sky direction is put for the lens map
  static constexpr double kStarCut = 3.0;    // a star's profile reaches kStarCut sizes (StarField::radiance)
  static constexpr double kStarBright = 0.2;  // the faintest star drawn, as a share of the field's brightness
  struct SkyStar {
    V3 dir;
    int sheet;
  };
  struct StarRef {
    int star;
    double p;  // its probability in the pixel
  };

  const Scene& sc_;
  const CameraRays<M>& cam_;
  const LensConnection<M>& lens_;
  int threads_;
  LensVertex v_;               // the camera as a lens vertex (no normal)
  LinearMap from_local_;       // v_.to_local's inverse
  double pixel_solid_ = 0.0;   // the solid angle of a pixel at the image's centre
  std::vector<int> slot_;      // per image pixel: its row of share_, or -1 (empty: the strategy is off)
  std::vector<double> share_;  // per slot, each light's probability of being chosen there
  struct UvBox {
    double lo1 = 0.0, hi1 = 1.0, lo2 = 0.0, hi2 = 1.0;
    double area() const { return (hi1 - lo1) * (hi2 - lo2); }
  };
  std::vector<UvBox> box_;     // per slot and light, the sampling numbers its light samples draw from
  std::vector<uint8_t> orders_;     // per image pixel, the image orders its samples solve for
  std::vector<SkyStar> stars_;      // the stars some pixel draws
  std::vector<size_t> star_off_;    // per image pixel, its range of star_list_ (empty: no pixel draws stars)
  std::vector<StarRef> star_list_;  // the pixels' stars, pixel by pixel
};

}  // namespace wv
