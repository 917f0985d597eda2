// Photons for caustics (photon_map.h): light paths that leave the lights as null geodesics, traced segment by
// segment by the camera paths' own segment tracer (segment.h: closed-form orbits, integrated steps, SIMD
// lanes), through mirrors and glass, and stored where they first reach a diffuse surface after at least one
// specular vertex (light -> specular+ -> diffuse: the caustic paths, which the path tracer finds only when
// a BSDF direction happens to hit a light after a specular chain); with o.retro_photons also where they first
// reach one straight from a light along a segment that turned by more than 120 degrees (light the hole turns
// back, round the photon orbits: retro_segment). In flat space and static spherical metrics
// (Schwarzschild, Reissner-Nordstrom, Ellis) the spatial path of light is the same traced either way in time,
// so a backward segment along the emitted direction is the photon's path (closed forms included); in any other
// (Kerr, metrics from a line element) the photon is integrated forward in time, its future-directed momentum
// leaving along the emitted direction (frame dragging bends it the other way from a camera ray's).
//
// A photon's flux is what the path tracer's measurement gives the same path: a light chosen by its power, a
// point on it by area, a direction cosine-weighted about its normal in the local observer's frame there (the
// static observer, or the ZAMO where none is static), so
//   flux = Le pi A J_L sides / (P(light) N),
// A the light's user-frame area, J_L = dA_proper / dA_user at the point (the local frame's map), N the pass's
// photons. The path tracer keeps radiance along a geodesic (a lamp that does not beam); the product
// cos dOmega dA of a ray bundle is not kept in curved space but nu^2 cos dOmega dA is (the photons in phase
// space), so the flux a photon brings to a surface whose local observer sees its frequency shifted by g
// (nu_surface / nu_light) is the emitted one times g^-2. The camera side (path_tracer.h) divides by the
// proper area pi r^2 J_S of its gather disk. Beaming emitters send no photons; the path tracer keeps their
// caustics.
//
// Photon i of pass j draws its random numbers from Rng(photon_seed(seed), j, i), and a pass's photons are
// stored in photon order: a pass is a function of (seed, j) alone, whatever the threads.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/parallel.h"
#include "core/rng.h"
#include "core/task.h"
#include "core/vec3.h"
#include "integrators/chart_geometry.h"
#include "integrators/photon_aim.h"
#include "integrators/photon_map.h"
#include "integrators/render_types.h"
#include "integrators/sample_scheduler.h"
#include "integrators/segment.h"
#include "scene/light.h"
#include "scene/material.h"
#include "scene/scene.h"

namespace wv {

// The seed of the photons' random numbers (a 64-bit mix of the render's).
inline uint64_t photon_seed(uint64_t seed) { return mix64(seed ^ 0x3c6ef372fe94f82bull); }

template <class M, class S>
class PhotonTracer {
 public:
  using Scheduler = SampleScheduler<M, S>;
  static constexpr size_t kTaskPhotons = 256;  // photons (or the aim's rays) per parallel task
  // Flat and static spherical metrics trace photons as backward segments (the same spatial path, and their
  // closed forms); any other is integrated forward in time.
  static constexpr bool kTimeSymmetric = M::kFlat || M::kStaticSpherical;

  PhotonTracer(const M& m, const Scene& sc, const RenderOptions& o)
      : m_(m), sc_(sc), o_(o), segments_(m, sc, o, !kTimeSymmetric), geo_(m), point_frames_(point_light_frames(m, sc)),
        retro_(o.retro_photons && !exact_light_strategy<M>(o)) {
    emits_.assign(sc.prims.size(), 0);
    double total = 0.0;
    for (const int p : sc.lights) {
      const double w = power(p);
      if (!(w > 0.0)) continue;
      emits_[p] = 1;
      lights_.push_back(p);
      cdf_.push_back(total += w);
    }
    for (size_t k = 0; k < sc.point_lights.size(); ++k) {  // (point light k as -1 - k)
      const PointLight& pl = sc.point_lights[k];
      const double w = (pl.intensity.x + pl.intensity.y + pl.intensity.z) / 3.0 * pl.solid_angle();
      if (!(w > 0.0 && std::isfinite(w)) || !point_frames_[k].ok) continue;
      lights_.push_back(-1 - int(k));
      cdf_.push_back(total += w);
    }
    for (double& c : cdf_) c /= total;
    if (o.photon_aim && !lights_.empty()) {
      if (o.photon_aim_marks) {
        if (o.photon_aim_marks->lights() != lights_.size())
          throw std::invalid_argument("render option 'photon_aim_marks' holds the marks of " +
                                      std::to_string(o.photon_aim_marks->lights()) + " photon lights; this scene has " +
                                      std::to_string(lights_.size()));
        aim_ = o.photon_aim_marks;
      } else {
        auto built = std::make_shared<PhotonAim>();
        build_aim(*built);
        aim_ = built;
      }
    }
  }

  // Whether prim p sends photons (a light that does not beam): the caustics its light makes on diffuse
  // surfaces are the photons', so the path tracer leaves them out.
  bool sends_photons(int p) const { return p >= 0 && size_t(p) < emits_.size() && emits_[p]; }
  bool any_light() const { return !lights_.empty(); }
  // The photons' marks (PhotonAim; null without photon_aim), and the segments learning them cost here (none where
  // they were handed in).
  const std::shared_ptr<const PhotonAim>& aim() const { return aim_; }
  const RenderStats& aim_stats() const { return aim_stats_; }

  // The light a hole turns back (o.retro_photons): whether a segment that reached photon light `prim`, or left
  // it, turned by more than 120 degrees between its ends (its directions of travel there, each in its local
  // frame: the same for the geodesic traced either way). Such light reaches a diffuse surface round the photon
  // orbits, where a light strategy without the spacetime's exact lens map (Kerr, line elements, the aimed
  // connection) cannot draw it; photons bring it instead, and the path tracer leaves it out in both strategies.
  // Where the light strategy is the exact lens map (static spherical metrics), it draws that light itself with
  // less noise than the photons' gather (a lamp over a hole lighting a ceiling: 4x less variance per sample),
  // so it keeps it (retro() false).
  static constexpr double kRetroCos = -0.5;
  bool retro() const { return retro_; }
  bool retro_segment(int prim, V3 start, V3 end) const {
    return retro_ && sends_photons(prim) && dot(start, end) < kRetroCos;
  }

  // Pass j's photon map: o.photons photons traced in parallel, stored in photon order. False: cancelled.
  bool pass(int64_t j, const std::function<bool()>& poll, PhotonMap& map, RenderStats& stats) const {
    map = PhotonMap();  // the last pass's photons are gathered no more: let them go before this pass's are stored
    const size_t n = size_t(std::max<int64_t>(0, o_.photons));
    if (lights_.empty() || n == 0) return true;
    const uint64_t seed = photon_seed(o_.seed);
    struct TaskPhotons {  // a task's photons while it runs, and those it stored, in photon order
      RenderStats stats;
      std::vector<Photon> out, stored;
      std::vector<char> hit;
    };
    std::vector<TaskPhotons> tasks;
    auto make = [&](size_t i, TaskPhotons& t, Scheduler* sched) {
      if (t.out.empty()) {  // (a task's photons start on its worker, its first one first)
        t.out.resize(kTaskPhotons);
        t.hit.assign(kTaskPhotons, 0);
      }
      return trace(seed, j, int64_t(i), double(n), t.stats, sched, t.out[i % kTaskPhotons], t.hit[i % kTaskPhotons]);
    };
    auto finish = [&](size_t k) {  // the task's stored photons kept, its buffers let go
      TaskPhotons& t = tasks[k];
      t.stored.reserve(size_t(std::count_if(t.hit.begin(), t.hit.end(), [](char h) { return h != 0; })));
      for (size_t i = 0; i < t.out.size(); ++i)
        if (t.hit[i]) t.stored.push_back(t.out[i]);
      t.out = std::vector<Photon>();
      t.hit = std::vector<char>();
    };
    if (!run_tasks<M, S>(m_, o_.batch, o_.threads, n, kTaskPhotons, tasks, make, poll, finish)) return false;
    // At most kPhotonPassBytes per photon at once (every photon stored): the stored ones gathered (each task's let
    // go as it is copied), then the tree's photons and its reordered copy, its index and axes (PhotonMap).
    size_t count = 0;
    for (const TaskPhotons& t : tasks) count += t.stored.size();
    std::vector<Photon> all;
    all.reserve(count);
    for (TaskPhotons& t : tasks) {
      all.insert(all.end(), t.stored.begin(), t.stored.end());
      t.stored = std::vector<Photon>();
      stats.segments += t.stats.segments;
      stats.steps += t.stats.steps;
    }
    map = PhotonMap(std::move(all));
    return true;
  }

 private:
  // A light's power up to a constant (its choice probability): area x radiance scale x sides.
  double power(int p) const {
    const Prim& pr = sc_.prims[p];
    const Material& mat = sc_.materials[pr.material];
    if (mat.beaming || mat.keplerian) return 0.0;
    double area = 0.0;
    if (pr.kind == PrimKind::kSphere) {
      area = 2.0 * kTwoPi * sc_.spheres[pr.index].radius * sc_.spheres[pr.index].radius;
    } else {
      LightPoint lp;
      if (!sample_light_point(sc_, p, {0, 0, 0}, 0.5, 0.5, lp)) return 0.0;
      area = lp.area;
    }
    const double scale = mat.emission_scale();
    const double sides = mat.kind == MaterialKind::kEmissive && mat.two_sided ? 2.0 : 1.0;
    const double w = area * scale * sides;
    return std::isfinite(w) && w > 0.0 ? w : 0.0;
  }

  // Where a photon leaves an area light (the point drawn by (u1, u2), the side by us): its user-frame point, the
  // surface there, the local-frame normal and that of the side it leaves from, and pi A J sides (A the light's
  // user-frame area, J = dA_proper / dA_user there).
  struct Start {
    V3 pos, nl, nl_out;
    SurfacePoint sp;
    double scale = 0.0;
    int side = 0;  // (PhotonAim's: 1 the back of a two-sided light)
  };
  bool start_at(int p, double u1, double u2, double us, Start& s) const {
    const Prim& pr = sc_.prims[p];
    const Material& mat = sc_.materials[pr.material];
    LightPoint lp;
    if (pr.kind == PrimKind::kSphere) {  // the whole sphere
      const Sphere& sph = sc_.spheres[pr.index];
      const double z = 1.0 - 2.0 * u1, rxy = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = kTwoPi * u2;
      lp.normal = {rxy * std::cos(phi), rxy * std::sin(phi), z};
      lp.pos = sph.center + lp.normal * sph.radius;
      lp.area = 2.0 * kTwoPi * sph.radius * sph.radius;
    } else if (!sample_light_point(sc_, p, {0, 0, 0}, u1, u2, lp)) {
      return false;
    }
    const bool two = mat.kind == MaterialKind::kEmissive && mat.two_sided;
    s.side = two && us < 0.5 ? 1 : 0;
    const V3 n_out = s.side ? -lp.normal : lp.normal;  // the side the photon leaves from
    s.pos = lp.pos;
    s.sp = sc_.surface(p, lp.pos);
    s.nl = s.sp.normal;
    s.nl_out = n_out;  // local frame: the surface's normal and the side's
    double J = 1.0;
    if constexpr (!M::kFlat) {
      const StartFrames::Entry f = geo_.start_frame(lp.pos, pr.sheet);
      if (!f.ok) return false;
      s.nl = geo_.local_normal(f.x4, f.f, s.sp.normal);
      s.nl_out = dot(n_out, s.sp.normal) >= 0.0 ? s.nl : -s.nl;
      const LinearMap L = geo_.local_map(f.x4, f.f);
      V3 t, b;
      basis_around(s.sp.normal, t, b);
      J = length(cross(L(t), L(b)));
    }
    s.scale = M_PI * lp.area * J * (two ? 2.0 : 1.0);
    return true;
  }

  // PhotonAim::draw, where there are marks.
  double draw_direction(size_t l, int part, double& v1, double& v2) const {
    return aim_ ? aim_->draw(l, part, v1, v2) : 1.0;
  }

  // A point light's direction (local frame) from the emission square's (v1, v2): uniform in its sky or its cone
  // (c: the cosine to its axis).
  V3 point_direction(size_t k, double v1, double v2, double& c) const {
    const PointLight& pl = sc_.point_lights[k];
    c = 1.0 - v1 * (1.0 - (pl.spot ? pl.cos_outer : -1.0));
    const double phi = kTwoPi * v2, s = std::sqrt(std::max(0.0, 1.0 - c * c));
    V3 t, b;
    basis_around(point_frames_[k].axis_local, t, b);
    return point_frames_[k].axis_local * c + t * (s * std::cos(phi)) + b * (s * std::sin(phi));
  }

  // PhotonAim's marks: rays from each part of each light along the middles of the emission square's cells, in
  // rounds (the coarse cells; the fine cells of those that reached something; the flood round the fine cells
  // that did), each round's rays traced in parallel as the photons are.
  void build_aim(PhotonAim& aim) {
    using A = PhotonAim;
    constexpr int N = A::kFine * A::kFine;
    aim.resize(lights_.size());
    struct Ray {
      uint32_t unit;  // light slot x A::kParts + part
      uint16_t cell;  // a coarse cell (I + kCoarse J) or a fine one (i + kFine j)
      bool fine;
    };
    const size_t units = lights_.size() * A::kParts;
    std::vector<std::vector<char>> traced(units), reached(units);
    std::vector<Ray> rays;
    // The lights by power, as many as A::kMaxParts parts allow (an emissive mesh's thousand triangles would cost a
    // thousand lights' rays: the rest send their photons unaimed).
    std::vector<size_t> order(lights_.size());
    std::iota(order.begin(), order.end(), size_t(0));
    auto share = [&](size_t l) { return cdf_[l] - (l > 0 ? cdf_[l - 1] : 0.0); };
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return share(a) > share(b); });
    int parts_left = A::kMaxParts;
    for (const size_t l : order) {
      const int p = lights_[l];
      const bool two = p >= 0 && sc_.materials[sc_.prims[p].material].kind == MaterialKind::kEmissive &&
                       sc_.materials[sc_.prims[p].material].two_sided;
      const int parts = p < 0 ? 1 : (two ? 2 : 1) * A::kPointCells * A::kPointCells;
      if (parts > parts_left) continue;
      parts_left -= parts;
      for (int part = 0; part < A::kParts; ++part) {
        int i, j, side;
        A::part_cell(part, i, j, side);
        if ((p < 0 && part != 0) || (side == 1 && !two)) continue;  // (a point light: one part)
        const size_t u = l * A::kParts + size_t(part);
        traced[u].assign(N, 0);
        reached[u].assign(N, 0);
        for (int c = 0; c < A::kCoarse * A::kCoarse; ++c) rays.push_back({uint32_t(u), uint16_t(c), false});
      }
    }
    auto push_fine = [&](std::vector<Ray>& next, size_t u, int c) {
      if (traced[u][size_t(c)]) return;
      traced[u][size_t(c)] = 1;
      next.push_back({uint32_t(u), uint16_t(c), true});
    };
    while (!rays.empty()) {
      std::vector<char> useful(rays.size(), 0);
      std::vector<RenderStats> task_stats;
      run_tasks<M, S>(m_, o_.batch, o_.threads, rays.size(), kTaskPhotons, task_stats,
                      [&](size_t k, RenderStats& st, Scheduler* sched) { return aim_ray(rays[k], useful[k], st, sched); });
      for (const RenderStats& st : task_stats) aim_stats_.add(st);
      std::vector<Ray> next;
      std::vector<std::vector<int>> coarse(units);
      for (size_t k = 0; k < rays.size(); ++k) {
        const Ray& r = rays[k];
        if (!r.fine) {
          if (useful[k]) coarse[r.unit].push_back(r.cell);
          continue;
        }
        if (!useful[k]) continue;
        reached[r.unit][r.cell] = 1;
        A::around(r.cell, [&](int c) { push_fine(next, r.unit, c); });
      }
      for (size_t u = 0; u < units; ++u) {
        if (coarse[u].empty()) continue;
        const bool flood = int(coarse[u].size()) <= A::kFloodLimit;
        for (const int c : coarse[u]) {  // its fine cells; too many: marked whole, grown by one coarse cell
          const int I = c % A::kCoarse, J = c / A::kCoarse, g = flood ? 0 : 1;
          for (int dJ = -g; dJ <= g; ++dJ)
            for (int dI = -g; dI <= g; ++dI)
              for (int b = 0; b < A::kRatio; ++b)
                for (int a = 0; a < A::kRatio; ++a) {
                  const int i = (I + dI) * A::kRatio + a, j = (J + dJ) * A::kRatio + b;
                  if (flood) {
                    push_fine(next, u, i + A::kFine * j);
                  } else if (i >= 0 && i < A::kFine) {
                    const size_t f = size_t(i + A::kFine * ((j + A::kFine) % A::kFine));
                    traced[u][f] = reached[u][f] = 1;
                  }
                }
        }
      }
      rays = std::move(next);
    }
    // The marks: the fine cells that reached something, grown by one.
    for (size_t u = 0; u < units; ++u) {
      if (reached[u].empty()) continue;
      std::vector<char> mark(N, 0);
      for (int c = 0; c < N; ++c) {
        if (reached[u][size_t(c)]) A::around(c, [&](int f) { mark[size_t(f)] = 1; });
      }
      std::vector<uint16_t>& m = aim.marks(u / A::kParts, int(u % A::kParts));
      for (int c = 0; c < N; ++c)
        if (mark[size_t(c)]) m.push_back(uint16_t(c));
      if (int(m.size()) == N) m.clear();  // (everything: nothing to aim at)
    }
  }

  // One of PhotonAim's rays: from a point of its part of the light (spread over it) along its cell's middle;
  // `useful` if a photon sent there could be stored (follow): it reaches a mirror or glass, or a diffuse surface
  // turned back by the hole where photons carry that light.
  template <class Ray>
  Task<void> aim_ray(const Ray& r, char& useful, RenderStats& st, Scheduler* sched) const {
    using A = PhotonAim;
    const size_t l = r.unit / A::kParts;
    const int part = int(r.unit % A::kParts), p = lights_[l];
    const int cells = r.fine ? A::kFine : A::kCoarse;
    const double v1 = (r.cell % cells + 0.5) / cells, v2 = (r.cell / cells + 0.5) / cells;
    V3 x, w;
    int sheet;
    if (p < 0) {
      double c;
      w = point_direction(size_t(-1 - p), v1, v2, c);
      x = sc_.point_lights[size_t(-1 - p)].pos;
      sheet = sc_.point_lights[size_t(-1 - p)].sheet;
    } else {
      int i, j, side;
      A::part_cell(part, i, j, side);
      double a, b;
      A::spread(r.cell + (r.fine ? A::kCoarse * A::kCoarse : 0), a, b);
      Start s;
      if (!start_at(p, (i + a) / A::kPointCells, (j + b) / A::kPointCells, side ? 0.25 : 0.75, s)) co_return;
      w = cosine_direction(s.nl_out, v1, v2);
      x = offset(s.pos, s.sp.normal, s.nl, w);
      sheet = sc_.prims[p].sheet;
    }
    PathFrames<M> frames;
    SegmentEnd e;
    co_await segments_.segment(x, sheet, w, p < 0 ? -1 : p, nullptr, st, frames, sched, e);
    if (e.status != kHit) co_return;
    const Material& hm = sc_.materials[sc_.prims[e.prim].material];
    useful = hm.kind == MaterialKind::kDiffuse ? retro_segment(p, w, e.dir) : hm.is_delta();
  }

  // Photon i of pass j (n photons in the pass): into `out`, with `stored` set, if it reaches a diffuse surface
  // after at least one specular vertex within o.max_depth segments. Its direction is drawn in the emission
  // square of its part of the light (aim_.draw), its flux divided by that draw's density ratio.
  Task<void> trace(uint64_t seed, int64_t j, int64_t i, double n, RenderStats& st, Scheduler* sched, Photon& out,
                   char& stored) const {
    Rng rng(seed, uint64_t(j), uint64_t(i));
    // The light, by its power.
    const double ul = rng.uniform();
    const size_t li = std::min(lights_.size() - 1,
                               size_t(std::upper_bound(cdf_.begin(), cdf_.end(), ul) - cdf_.begin()));
    const double p_light = cdf_[li] - (li > 0 ? cdf_[li - 1] : 0.0);
    const int p = lights_[li];
    if (p < 0) {  // a point or spot light: a direction uniform in its sky or its cone, in its local frame
      const PointLight& pl = sc_.point_lights[size_t(-1 - p)];
      double v1 = rng.uniform();
      double v2 = rng.uniform();
      const double ratio = draw_direction(li, 0, v1, v2);
      double c;
      const V3 w = point_direction(size_t(-1 - p), v1, v2, c);
      const V3 power = pl.intensity * (pl.profile(c) * pl.solid_angle() / (p_light * n * ratio));
      if (!(max_component(power) > 0.0)) co_return;
      co_await follow(pl.pos, pl.sheet, w, -1, power, rng, st, sched, out, stored);
      co_return;
    }
    // A point on it by area, and the side it leaves from.
    const double u1 = rng.uniform(), u2 = rng.uniform(), us = rng.uniform();
    Start s;
    if (!start_at(p, u1, u2, us, s)) co_return;
    double v2 = rng.uniform();  // (drawn in this order before the aim: the same photons without it)
    double v1 = rng.uniform();
    const double ratio = draw_direction(li, PhotonAim::part(u1, u2, s.side), v1, v2);
    const V3 w = cosine_direction(s.nl_out, v1, v2);
    const V3 Le = sc_.emitted(p, s.sp, s.nl, w);
    const V3 power = Le * (s.scale / (p_light * n * ratio));
    if (!(max_component(power) > 0.0)) co_return;
    co_await follow(offset(s.pos, s.sp.normal, s.nl, w), sc_.prims[p].sheet, w, p, power, rng, st, sched, out,
                    stored);
  }

  // A photon of flux `power` from user-frame point x on `sheet` along local direction d (leaving prim `skip`),
  // followed through mirrors and glass to where it is stored (`out`, `stored`) or lost.
  Task<void> follow(V3 x, int sheet, V3 d, int skip, V3 power, Rng& rng, RenderStats& st, Scheduler* sched,
                    Photon& out, char& stored) const {
    PathFrames<M> frames;
    int specular = 0;
    const V3 d0 = d;  // the direction it left the light along
    double g = 1.0;  // nu at the segment's end over nu at the light
    double first_step = 0.0;  // the last segment's last step, where the next one starts (SegmentTracer::segment)
    for (int k = 0; k < o_.max_depth; ++k) {
      SegmentEnd e;
      co_await segments_.segment(x, sheet, d, skip, nullptr, st, frames, sched, e, first_step);
      if (e.status != kHit) co_return;
      if constexpr (!M::kFlat) g *= e.energy;
      const Material& hm = sc_.materials[sc_.prims[e.prim].material];
      if (hm.kind == MaterialKind::kDiffuse) {
        // direct light: the path tracer's, but for light the hole turned back
        if (specular == 0 && !retro_segment(skip, d0, e.dir)) co_return;
        out.pos = e.pos;
        out.n_in = e.surface.normal * arrival_side(e);  // (the side the photon came from)
        out.power = power / (g * g);
        out.sheet = e.sheet;
        out.segments = k + 1;
        stored = finite(out.power) ? 1 : 0;
        co_return;
      }
      if (!hm.is_delta()) co_return;  // an emitter absorbs
      const double v1 = rng.uniform(), v2 = rng.uniform(), v3 = rng.uniform();
      const BsdfSample bs = bsdf_sample(hm, {1, 1, 1}, e.normal_local, -e.dir, v1, v2, v3);
      if (!bs.valid) co_return;
      power *= bs.weight;
      if (!(max_component(power) > 0.0)) co_return;
      ++specular;
      x = offset(e.pos, e.surface.normal, e.normal_local, bs.wi);
      d = bs.wi;
      sheet = e.sheet;
      skip = e.prim;
      first_step = e.step;
    }
  }

  const M& m_;
  const Scene& sc_;
  const RenderOptions& o_;
  SegmentTracer<M, S> segments_;
  ChartGeometry<M> geo_;
  std::vector<PointLightFrame> point_frames_;
  std::vector<char> emits_;   // per prim: sends photons
  std::vector<int> lights_;   // the prims that send photons, and point light k as -1 - k
  std::vector<double> cdf_;   // their choice by power, cumulative
  bool retro_;                // photons carry the light a hole turns back (retro_segment)
  std::shared_ptr<const PhotonAim> aim_;  // where photons are worth sending (o.photon_aim; null: everywhere alike)
  RenderStats aim_stats_;     // the segments its marks cost
};

}  // namespace wv
