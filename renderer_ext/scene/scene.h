// A renderable scene: primitives with materials and textures, the sky on each sheet, the camera and the
// list of lights, with one BVH over everything. Built once (bindings/scene_dict.cpp) and then read-only,
// so any number of threads share it.
#pragma once

#include <string>
#include <type_traits>
#include <vector>

#include "scene/bvh.h"
#include "scene/environment.h"
#include "scene/material.h"
#include "scene/shapes.h"
#include "scene/texture.h"
#include "spacetime/observers.h"

namespace wv {

// Set in full from the native scene dict (bindings/scene_dict.cpp); its defaults live in Python
// (warpviz/scene/native.py), not here.
// What a moving camera does with the shift g = nu_camera / nu_seen of the light it receives (the first
// surface's local observer, or the sky at infinity, to the camera): nothing (radiance as the local observer
// there sees it), beaming (bolometric radiance times g^4) or the colour shift as well (emission.h).
// Emitters that shift their own light (beaming materials) are shifted once, by their own rule.
enum CameraShift : int { kShiftNone = 0, kShiftBeaming = 1, kShiftColour = 2 };

struct Camera {
  V3 position{0, 0, 0}, look_at{0, 0, 0}, up{0, 0, 0};
  double fov = 0.0;  // vertical, degrees
  int width = 0, height = 0;
  int sheet = 0;
  ObserverSpec observer;  // who holds the camera (spacetime/observers.h); kLocal: the local static observer
  int shift = kShiftNone;
};

// A point light, or a spot light: radiant intensity `intensity` (per colour channel, per steradian of the local
// static observer's sky at pos) towards every direction, or within a cone about `axis` (user frame), full
// inside cos_inner and falling smoothly to 0 at cos_outer. No ray ever hits one: the light strategy and the
// photons reach it (path_tracer.h, photon_tracer.h).
struct PointLight {
  V3 pos;
  int sheet = 1;
  V3 intensity{0, 0, 0};
  bool spot = false;
  V3 axis{0, 0, 1};
  double cos_outer = -1.0, cos_inner = -1.0;
  // The share of the intensity sent at cos_axis = cos(angle from the axis): 1 for a point light, a
  // smoothstep from the cone's edge inwards for a spot light.
  double profile(double cos_axis) const {
    if (!spot || cos_axis >= cos_inner) return 1.0;
    if (cos_axis <= cos_outer) return 0.0;
    const double t = (cos_axis - cos_outer) / (cos_inner - cos_outer);
    return t * t * (3.0 - 2.0 * t);
  }
  // The solid angle its directions are drawn from (photons): the whole sky, or the spot's cone.
  double solid_angle() const { return spot ? kTwoPi * (1.0 - cos_outer) : 2.0 * kTwoPi; }
};

class Scene {
 public:
  std::vector<Sphere> spheres;
  std::vector<Quad> quads;
  std::vector<Disk> disks;
  std::vector<Triangle> triangles;
  std::vector<Prim> prims;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<int> lights;  // prims that emit and can be sampled (spheres, quads, disks)
  std::vector<PointLight> point_lights;  // the light strategy's lights lights.size() ... light_count() - 1
  int light_count() const { return int(lights.size() + point_lights.size()); }
  Environment environment, environment_other;
  Camera camera;
  Bvh bvh;
  double bound_radius = 0.0;  // every primitive lies within this distance of the origin

  // Call after filling the arrays: builds the BVH, the light list and the bounds.
  void finalize();

  bool intersect_prim(int p, V3 o, V3 d, double tmin, double tmax, double& t) const {
    const Prim& pr = prims[p];
    switch (pr.kind) {
      case PrimKind::kSphere: return intersect(spheres[pr.index], o, d, tmin, tmax, t);
      case PrimKind::kQuad: return intersect(quads[pr.index], o, d, tmin, tmax, t);
      case PrimKind::kDisk: return intersect(disks[pr.index], o, d, tmin, tmax, t);
      default: return intersect(triangles[pr.index], o, d, tmin, tmax, t);
    }
  }
  double implicit_at(int p, V3 x) const {
    const Prim& pr = prims[p];
    switch (pr.kind) {
      case PrimKind::kSphere: return implicit(spheres[pr.index], x);
      case PrimKind::kQuad: return implicit(quads[pr.index], x);
      case PrimKind::kDisk: return implicit(disks[pr.index], x);
      default: return implicit(triangles[pr.index], x);
    }
  }
  // The unit normal of a flat primitive (quad, disk, triangle: implicit_at is the signed distance from its
  // plane), or null (a sphere).
  const V3* plane_normal(int p) const {
    const Prim& pr = prims[p];
    switch (pr.kind) {
      case PrimKind::kSphere: return nullptr;
      case PrimKind::kQuad: return &quads[pr.index].normal;
      case PrimKind::kDisk: return &disks[pr.index].normal;
      default: return &triangles[pr.index].normal;
    }
  }
  // plane_gap (shapes.h) of a flat primitive; 0 for a sphere.
  double plane_gap(int p, V3 x) const {
    const Prim& pr = prims[p];
    switch (pr.kind) {
      case PrimKind::kSphere: return 0.0;
      case PrimKind::kQuad: return wv::plane_gap(quads[pr.index], x);
      case PrimKind::kDisk: return wv::plane_gap(disks[pr.index], x);
      default: return wv::plane_gap(triangles[pr.index], x);
    }
  }
  SurfacePoint surface(int p, V3 x) const {
    const Prim& pr = prims[p];
    switch (pr.kind) {
      case PrimKind::kSphere: return surface_at(spheres[pr.index], x);
      case PrimKind::kQuad: return surface_at(quads[pr.index], x);
      case PrimKind::kDisk: return surface_at(disks[pr.index], x);
      default: return surface_at(triangles[pr.index], x);
    }
  }

  // Closest hit of the segment o + t d, t in (tmin, tmax), among primitives on `sheet`; `skip` is a
  // primitive ignored for t < skip_t (the surface a ray just left). skip_t is a number, or a callable that
  // gives it, called only if the ray meets `skip` (a whole ray's start distance costs a square root).
  template <class SkipT>
  bool closest_hit(V3 o, V3 d, double tmin, double tmax, int sheet, int skip, const SkipT& skip_t,
                   SegmentHit& hit) const {
    return bvh.closest(
        o, d, tmin, tmax,
        [&](int p, V3 oo, V3 dd, double t0, double t1, double& t) {
          if (prims[p].sheet != sheet) return false;
          if (!intersect_prim(p, oo, dd, t0, t1, t)) return false;
          if constexpr (std::is_invocable_v<SkipT>) {
            if (p == skip && t < skip_t()) return false;
          } else {
            if (p == skip && t < skip_t) return false;
          }
          return true;
        },
        hit);
  }

  V3 albedo(const Material& m, const SurfacePoint& sp) const {
    return m.texture >= 0 ? textures[m.texture].eval(sp.u, sp.v) : V3{0.8, 0.8, 0.8};
  }
  // Radiance emitted by primitive p at surface point sp towards unit direction w (local frame; nl is the
  // local-frame normal).
  V3 emitted(int p, const SurfacePoint& sp, V3 nl, V3 w) const {
    const Material& m = materials[prims[p].material];
    if (m.kind != MaterialKind::kEmissive) {
      if (!(max_component(m.emission) > 0.0) || dot(nl, w) <= 0.0) return {0, 0, 0};
      return m.emission;
    }
    if (!m.two_sided && dot(nl, w) <= 0.0) return {0, 0, 0};
    const V3 c = m.texture >= 0 ? textures[m.texture].eval(sp.u, sp.v) : V3{1, 1, 1};
    return c * m.strength;
  }
  const Environment& sky(int sheet) const { return sheet >= 0 ? environment : environment_other; }
};

}  // namespace wv
