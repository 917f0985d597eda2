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
// both strategies then weigh what they find at x by 1 / (1 + rho(x)): a camera ray that first hits light point B
// (weight 1 / (1 + rho), rho that of the image of B it is), and a light sample whose image lands in the pixel
// and whose ray first hits B (L / rho times rho / (1 + rho)). Both know rho from the image point alone, so the
// estimate stays unbiased whatever the lens map's accuracy; where the light strategy cannot reach (an image of
// order >= lens_images, the far half of a sphere) rho is 0 and the camera ray counts alone.
//
// The pixels it runs in, and the lights it picks there, come from the scene alone: kGrid^2 points on each light
// (by area, as sample_light_point draws them from the camera) are mapped into the image, and a pixel where a
// light's points land with probability >= kMinShare per light sample gets the strategy, choosing among the lights
// in proportion to how many of their points land in it. A lamp seen large is left to the camera rays, which see
// its inside without noise. Every window and tile of an image agrees on it.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/vec3.h"
#include "integrators/camera.h"
#include "integrators/lens_connection.h"
#include "integrators/render_types.h"
#include "scene/light.h"
#include "scene/scene.h"
#include "spacetime/lens_map.h"

namespace wv {

// One image of a light point that a light sample drew for a pixel: the camera ray's local direction, the light
// prim and point it must first hit, and the strategy's density rho at its image point.
struct CameraShot {
  V3 w, target;
  int prim = -1;
  double rho = 0.0;
};

template <class M>
class CameraConnection {
 public:
  static constexpr int kGrid = 32;              // points per side on each light for the pixels' shares
  static constexpr double kMinShare = 1.0 / 32;  // a pixel's least share of a light sample to get the strategy

  // Active (o.camera_light_samples) where the lens connection is the light strategy of a static spherical metric,
  // the camera is static, sees no shift of its own, samples its pixels uniformly (the box filter of the pixel
  // itself) and lies where the lens map applies; `on`: the caller's other conditions (not a guide's training).
  CameraConnection(const Scene& sc, const RenderOptions& o, const CameraRays<M>& cam, const LensConnection<M>& lens,
                   bool on)
      : sc_(sc), cam_(cam), lens_(lens) {
    if constexpr (M::kStaticSpherical) {
      const V3 pos = sc.camera.position;
      const SphericalLens& sl = lens.lens();
      if (!on || !o.camera_light_samples || !o.light_sampling || o.light_connection != kLensConnection || sc.lights.empty() ||
          !cam.static_observer() || sc.camera.shift != kShiftNone || o.filter != kBoxFilter ||
          !(o.filter_radius == 0.0 || o.filter_radius == 0.5) || !(sl.u_inner > 0.0) ||
          !(length(pos) * sl.u_inner > 1.05))
        return;
      v_.pos = pos;
      v_.sheet = sc.camera.sheet;
      v_.to_local = cam.to_local();
      v_.radial_local = normalize(v_.to_local(normalize(pos)));
      const double aspect = double(sc.camera.width) / sc.camera.height;
      const double t = std::tan(0.5 * sc.camera.fov * M_PI / 180.0);
      pixel_solid_ = (2.0 * t * aspect / sc.camera.width) * (2.0 * t / sc.camera.height);
      build_shares();
    }
  }

  bool active() const { return !slot_.empty(); }

  // Whether image pixel (px, py) gets the strategy.
  bool applies(int px, int py) const {
    return !slot_.empty() && slot_[size_t(py) * size_t(sc_.camera.width) + size_t(px)] >= 0;
  }

  // rho of the camera ray of pixel (px, py) along local direction d, which first hits light prim p at user-frame
  // point x (0 where the light strategy never draws it).
  double rho(int px, int py, V3 d, int p, V3 x) const {
    const double pl = light_share(px, py, p);
    if (!(pl > 0.0)) return 0.0;
    LightPoint lp;
    if (!light_point_at(sc_, p, v_.pos, x, lp)) return 0.0;
    const LensImageRays rays = lens_image_rays(lens_.lens(), v_, lens_light(p, lp), lens_.orders());
    for (int k = 0; k < rays.n; ++k)
      if (dot(rays.ray[k].w, d) > 1.0 - kLensMatchCos) return density(rays, rays.ray[k], lp, pl);
    return 0.0;
  }

  // A light sample for pixel (px, py): u0 picks the light, u1, u2 the point on it; the images of the point that
  // land in the pixel (at most LensImages::kMax) are written to `out`. Returns how many.
  int sample(int px, int py, double u0, double u1, double u2, CameraShot* out) const {
    const size_t pix = size_t(py) * size_t(sc_.camera.width) + size_t(px);
    const int s = slot_[pix];
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
    LightPoint lp;
    if (!sample_light_point(sc_, p, v_.pos, u1, u2, lp)) return 0;
    const LensImageRays rays = lens_image_rays(lens_.lens(), v_, lens_light(p, lp), lens_.orders());
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
    const double jac = lens_area_jacobian(rays, ir, cos_n);  // |dA_B / dOmega|
    const double f = dot(ir.w, cam_.forward());               // the pinhole's dOmega / dx = f^3 pixel_solid_
    const double rho = pl / lp.area * jac * f * f * f * pixel_solid_;
    return rho > 0.0 && std::isfinite(rho) ? rho : 0.0;
  }

  double light_share(int px, int py, int p) const {
    const int s = slot_.empty() ? -1 : slot_[size_t(py) * size_t(sc_.camera.width) + size_t(px)];
    if (s < 0) return 0.0;
    const auto it = std::find(sc_.lights.begin(), sc_.lights.end(), p);
    if (it == sc_.lights.end()) return 0.0;
    return share_[size_t(s) * sc_.lights.size() + size_t(it - sc_.lights.begin())];
  }

  LensLight lens_light(int p, const LightPoint& lp) const {
    return LensLight{lp.pos, lp.normal, lp.area, sc_.prims[p].sheet, true};
  }

  // Each light's kGrid^2 points mapped into the image: a pixel's share of light l is the fraction of l's points
  // (images of every order the strategy draws) that land in it; pixels whose share of some light reaches
  // kMinShare get a slot, holding the lights' probabilities there (in proportion to their shares).
  void build_shares() {
    const int W = sc_.camera.width, H = sc_.camera.height, nl = int(sc_.lights.size());
    std::vector<std::vector<float>> count{size_t(nl)};
    for (int li = 0; li < nl; ++li) {
      const int p = sc_.lights[li];
      for (int i = 0; i < kGrid; ++i)
        for (int j = 0; j < kGrid; ++j) {
          LightPoint lp;
          if (!sample_light_point(sc_, p, v_.pos, (i + 0.5) / kGrid, (j + 0.5) / kGrid, lp)) continue;
          const LensImageRays rays = lens_image_rays(lens_.lens(), v_, lens_light(p, lp), lens_.orders());
          for (int k = 0; k < rays.n; ++k) {
            double x, y;
            if (!cam_.pixel_of(rays.ray[k].w, x, y)) continue;
            const double fx = std::floor(x), fy = std::floor(y);
            if (!(fx >= 0 && fy >= 0 && fx < W && fy < H)) continue;
            if (count[size_t(li)].empty()) count[size_t(li)].assign(size_t(W) * H, 0.0f);
            count[size_t(li)][size_t(fy) * W + size_t(fx)] += 1.0f;
          }
        }
    }
    const double need = kMinShare * kGrid * kGrid;
    std::vector<int> slot(size_t(W) * H, -1);
    bool any = false;
    for (size_t pix = 0; pix < slot.size(); ++pix) {
      double sum = 0.0, most = 0.0;
      for (int li = 0; li < nl; ++li) {
        const double c = count[size_t(li)].empty() ? 0.0 : count[size_t(li)][pix];
        sum += c;
        most = std::max(most, c);
      }
      if (!(most >= need)) continue;
      slot[pix] = int(share_.size() / size_t(nl));
      for (int li = 0; li < nl; ++li)
        share_.push_back(count[size_t(li)].empty() ? 0.0 : count[size_t(li)][pix] / sum);
      any = true;
    }
    if (any) slot_ = std::move(slot);
  }

  const Scene& sc_;
  const CameraRays<M>& cam_;
  const LensConnection<M>& lens_;
  LensVertex v_;               // the camera as a lens vertex (no normal)
  double pixel_solid_ = 0.0;   // the solid angle of a pixel at the image's centre
  std::vector<int> slot_;      // per image pixel: its row of share_, or -1 (empty: the strategy is off)
  std::vector<double> share_;  // per slot, each light's probability of being chosen there
};

}  // namespace wv
