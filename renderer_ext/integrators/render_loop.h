// The render loop: progressive passes (1, 1, 2, 4, ... samples per pixel, so an interrupted render is a
// whole image) over chunks of pixels in parallel, then further samples in the pixels on the edge of a
// light seen directly or in mirrors and glass and in those holding more than one surface (found first, by
// probe rays on a fixed lattice), progress and cancellation, and the film's accumulation of what the
// samples add, in (pixel, sample) order whatever order they finished in; the recorded pixels' segments and
// the segment statistics are collected on the way.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "core/vec3.h"
#include "film/film.h"
#include "integrators/guide_tree.h"
#include "integrators/render_types.h"
#include "integrators/sample_scheduler.h"
#include "scene/scene.h"
#include "spacetime/track.h"

namespace wv {

// What one sample adds to its pixel (summed later, in sample order).
struct SampleOut {
  V3 L{0, 0, 0};
  bool error = false;
  double max_drift = 0.0;
  int64_t steps = 0;
  V3 albedo{0, 0, 0}, albedo_normal{0, 0, 0};  // at the first non-specular hit (if the film keeps them)
  V3 emission{0, 0, 0};  // the part of L collected up to and at the first non-specular hit
  std::vector<RecordedSegment> rec;  // recorded pixels: this sample's segments
  std::vector<GuideRecord> guide;    // path guiding's training: this path's records (guide_training.h)
};

// Largest radiance one sample may carry (per channel): far above any scene's light (a sun seen from a
// room is ~1e5 of its lamp), far below where the film's float32 image and its sums of squares overflow.
constexpr double kMaxSampleRadiance = 1e30;

// Adds one sample to its pixel. A sample whose radiance is not finite or beyond kMaxSampleRadiance (an
// emitter of strength 1e308) is a failed sample that adds no light, not an infinite pixel.
inline void accumulate(Film& film, size_t pix, const SampleOut& so) {
  bool usable = true;
  for (int c = 0; c < 3; ++c) usable = usable && std::isfinite(so.L[c]) && std::abs(so.L[c]) <= kMaxSampleRadiance;
  for (int c = 0; c < 3 && usable; ++c) {
    film.rgb_sum[3 * pix + c] += so.L[c];
    film.rgb_sq_sum[3 * pix + c] += so.L[c] * so.L[c];
  }
  film.samples[pix] += 1;
  if (!usable) film.errors[pix] += 1;
  if (!film.steps_sum.empty()) film.steps_sum[pix] += double(so.steps);
  if (!film.max_drift.empty()) film.max_drift[pix] = std::max(film.max_drift[pix], float(so.max_drift));
  if (so.error && usable) film.errors[pix] += 1;
  if (!film.albedo_sum.empty())
    for (int c = 0; c < 3; ++c) film.albedo_sum[3 * pix + c] += so.albedo[c];
  if (!film.albedo_normal_sum.empty())
    for (int c = 0; c < 3; ++c) film.albedo_normal_sum[3 * pix + c] += so.albedo_normal[c];
  if (!film.emission_sum.empty() && usable)  // (a part of L: counted where L is)
    for (int c = 0; c < 3; ++c) film.emission_sum[3 * pix + c] += so.emission[c];
}

// The pixels of window (X0, Y0, W, H) that get more samples, found without random numbers (kPixelClasses *
// index + class, ascending): probe(x, y, stats, scheduler, hit) gives what the camera ray through image point
// (x, y) (pixel units) sees (ProbeHit: path_tracer.h); the probes lie on the lattice of half-pixel spacing
// (corners, edge midpoints and centres, shared by neighbours), a pixel's inner five only where its corners do
// not show it plain (below), which is judged by its corners. With `edges`, a pixel whose nine lattice points
// disagree on the emitters their branches end on, or one of which sees some (kProbeMixed), is an edge pixel
// (straddling the edge of a light seen directly or in mirrors and glass), a bright edge pixel where one of those
// points sees an emitter at radiance `bright` or more; so is a pixel none of whose lattice points sees a light
// where one more probe through a light's image point in it (images: light_image_points) sees one, or, on a hole's
// shadow edge, one of kRimProbes^2 more probes inside it does (thin lensed arcs). With `details`, one of the others
// whose lattice points disagree on where their branches end (two shapes, a shape and the sky or the hole) is
// a detail pixel. Depends only on the scene and the pixel, so every window agrees on it.
inline constexpr int kRimProbes = 8;  // (per side of a pixel on a shadow's edge)
template <class M, class S, class Probe>
std::vector<int64_t> pixel_classes(const M& m, const RenderOptions& o, int X0, int Y0, int W, int H,
                                   const Probe& probe, bool edges, bool details, const std::function<bool()>& poll,
                                   bool& cancelled, RenderStats& stats, const std::vector<double>& images = {},
                                   double bright = INFINITY) {
  // Probes through image points point(k, x, y), k < count, into out, in parallel tasks; false if cancelled.
  auto run_probes = [&](size_t count, const auto& point, std::vector<ProbeHit>& out) {
    out.assign(count, ProbeHit{});
    std::vector<RenderStats> task_stats;
    const bool done = run_tasks<M, S>(m, o.batch, o.threads, count, 256, task_stats,
                                      [&](size_t k, RenderStats& st, SampleScheduler<M, S>* sched) {
                                        double x, y;
                                        point(k, x, y);
                                        return probe(x, y, st, sched, out[k]);
                                      }, poll);
    for (const RenderStats& st : task_stats) stats.add(st);
    return done;
  };
  std::vector<int64_t> classes;
  const size_t LW = size_t(2 * W + 1), LH = size_t(2 * H + 1);
  std::vector<ProbeHit> hit(LW * LH);
  // The pixels' corners first, with a ring of one pixel round the window; then the other five lattice points of
  // each pixel that is not plain. A pixel is plain where the 16 corners of its 3 x 3 pixel neighbourhood show
  // nothing that its inner points could add: none sees a light or meets a mirror or glass, all fall in or none
  // does, and with `details` all end on the same shape. It is judged by its four corners alone: what could lie
  // between them unseen is smaller than a pixel and touches no corner within a pixel of it (the lights' thin arcs
  // are looked for by the probes below). The corners round the window make it depend on the scene and the
  // pixel only, as every class does.
  const size_t CW = size_t(W + 3), CH = size_t(H + 3);  // corner (i, j) at image point (X0 + i - 1, Y0 + j - 1)
  std::vector<ProbeHit> corner;
  cancelled = !run_probes(CW * CH, [&](size_t k, double& x, double& y) {
    x = X0 + double(k % CW) - 1.0;
    y = Y0 + double(k / CW) - 1.0;
  }, corner);
  if (cancelled) return classes;
  for (size_t j = 0; j + 2 < CH; ++j)
    for (size_t i = 0; i + 2 < CW; ++i) hit[2 * j * LW + 2 * i] = corner[(j + 1) * CW + i + 1];
  auto lattice = [&](int x, int y, int i, int j) -> const ProbeHit& {  // point (i, j) < 3 of pixel (x, y)'s nine
    return hit[size_t(2 * y + j) * LW + size_t(2 * x + i)];
  };
  std::vector<char> plain(size_t(W) * H, 0);
  std::vector<char> wanted(LW * LH, 0);
  std::vector<size_t> inner;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const ProbeHit& h0 = lattice(x, y, 0, 0);
      bool same = true;
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {  // corners x - 1 .. x + 2, y - 1 .. y + 2
          const ProbeHit& h = corner[size_t(y + j) * CW + size_t(x + i)];
          same = same && h.light == 0 && !h.specular && h.captured == h0.captured && (!details || h.shape == h0.shape);
        }
      plain[size_t(y) * W + size_t(x)] = same;
      if (same) continue;
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) {
          const size_t l = size_t(2 * y + j) * LW + size_t(2 * x + i);
          if ((i | j) & 1 && !wanted[l]) {
            wanted[l] = 1;
            inner.push_back(l);
          }
        }
    }
  std::vector<ProbeHit> inner_hit;
  cancelled = !run_probes(inner.size(), [&](size_t k, double& x, double& y) {
    x = X0 + 0.5 * double(inner[k] % LW);
    y = Y0 + 0.5 * double(inner[k] / LW);
  }, inner_hit);
  if (cancelled) return classes;
  for (size_t k = 0; k < inner.size(); ++k) hit[inner[k]] = inner_hit[k];
  // Pixel (x, y)'s lattice points: its nine, or a plain pixel's four corners.
  auto for_points = [&](int x, int y, const auto& f) {
    const int step = plain[size_t(y) * W + size_t(x)] ? 2 : 1;
    for (int j = 0; j < 3; j += step)
      for (int i = 0; i < 3; i += step) f(lattice(x, y, i, j));
  };
  auto dark = [&](int x, int y) {  // none of pixel (x, y)'s lattice points sees a light
    bool none = true;
    for_points(x, y, [&](const ProbeHit& h) { none = none && h.light == 0; });
    return none;
  };
  // A light's image point (images: light_image_points) in a dark pixel: one more probe through that point says
  // whether the image is seen there (not hidden): a thin lensed arc.
  std::vector<size_t> arc_pixels;
  std::vector<ProbeHit> arc_hit;
  if (edges && !images.empty()) {
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t c = size_t(y) * W + size_t(x);
        if (!std::isnan(images[2 * c]) && dark(x, y)) arc_pixels.push_back(c);
      }
    cancelled = !run_probes(arc_pixels.size(), [&](size_t k, double& x, double& y) {
      x = images[2 * arc_pixels[k]];
      y = images[2 * arc_pixels[k] + 1];
    }, arc_hit);
    if (cancelled) return classes;
  }
  // A dark pixel on a hole's shadow edge (some of its lattice probes fall in, some do not): kRimProbes^2 more
  // probes inside it look for the lights' thin images of higher order that crowd there (where no exact lens map
  // gives their points: in Kerr the lamp's arcs of order 1 and 2 round fig10d's hole, covering 2-20 % of a pixel at
  // 48 x 36, which the lattice missed).
  std::vector<size_t> rim_pixels;
  std::vector<ProbeHit> rim_hit;
  constexpr int K = kRimProbes;
  if (edges) {
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        bool in = false, out = false;
        for_points(x, y, [&](const ProbeHit& h) { (h.captured ? in : out) = true; });
        if (in && out && dark(x, y)) rim_pixels.push_back(size_t(y) * W + size_t(x));
      }
    cancelled = !run_probes(rim_pixels.size() * K * K, [&](size_t k, double& x, double& y) {
      const size_t c = rim_pixels[k / (K * K)];
      const int q = int(k % (K * K));
      x = X0 + double(c % size_t(W)) + (q % K + 0.5) / K;
      y = Y0 + double(c / size_t(W)) + (q / K + 0.5) / K;
    }, rim_hit);
    if (cancelled) return classes;
  }
  size_t next_arc = 0, next_rim = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const ProbeHit& h0 = lattice(x, y, 0, 0);
      bool edge = edges && h0.light == kProbeMixed, detail = false;
      double seen = 0.0;  // the brightest emitter its points see
      for_points(x, y, [&](const ProbeHit& h) {
        edge = edge || (edges && h.light != h0.light);  // (h0 is not mixed here, so a mixed point differs)
        detail = detail || (details && h.shape != h0.shape);
        seen = std::max(seen, double(h.radiance));
      });
      const size_t c = size_t(y) * W + size_t(x);
      if (next_arc < arc_pixels.size() && arc_pixels[next_arc] == c) {
        seen = std::max(seen, double(arc_hit[next_arc].radiance));
        edge = edge || arc_hit[next_arc++].light != 0;
      }
      if (next_rim < rim_pixels.size() && rim_pixels[next_rim] == c) {
        for (int q = 0; q < K * K; ++q) {
          const ProbeHit& h = rim_hit[next_rim * K * K + size_t(q)];
          seen = std::max(seen, double(h.radiance));
          edge = edge || h.light != 0;
        }
        ++next_rim;
      }
      if (edge || detail)
        classes.push_back(kPixelClasses * (int64_t(y) * W + x) +
                          (edge ? (seen >= bright ? kBrightEdgePixel : kEdgePixel) : kDetailPixel));
    }
  return classes;
}

// Renders camera `cam` (its window o.crop, if set): samples [B, B + o.spp) of every pixel, B = o.sample_begin,
// and [k B, k (B + o.spp)) of a pixel given k x o.spp (k = o.edge_samples on a light's edge, seen directly or in
// mirrors and glass, k = o.detail_samples where the pixel holds detail; pixel_classes, probed before any sample
// unless o.classes_given: which pixels they are does not depend on what the samples find, so every pixel's mean
// stays unbiased). Consecutive ranges therefore hold exactly the samples of one render of their total: a render
// can stop after any range and resume later. sample(px, py, s, film, out, recorded, stats, scheduler) is sample
// s of image pixel (px, py) as a Task (PathTracer::sample_pixel), run by run_samples; probe_lights: something
// emits, so a light has edges to probe for. A pixel's samples do not depend on the window, so windows of an
// image tile it exactly.
//
// With photon_pass (caustics by photons, photon_tracer.h), each sample gathers from a photon pass: sample s of
// a pixel given k x spp samples from photon pass floor(s / k), so the main pixels' samples [B, B1) and each
// group's [k B, k B1) use the passes [B, B1) (an edge or detail pixel's samples are all in its group's passes,
// the first range's too). The loop then goes photon pass by photon pass, photon_pass(j) making pass j current
// before the samples that use it (false: cancelled); a pixel's samples still come in sample order.
template <class M, class S, class Sample, class Probe>
RenderResult render_passes(const M& m, const Camera& cam, const RenderOptions& o, const Sample& sample,
                           const Probe& probe, bool probe_lights,
                           const std::function<bool(int64_t)>& photon_pass = {},
                           const std::function<std::vector<double>(int, int, int, int)>& light_images = {},
                           double bright_edge = INFINITY) {
  RenderResult out;
  const bool whole = o.crop[2] <= 0 || o.crop[3] <= 0;
  const int X0 = whole ? 0 : o.crop[0], Y0 = whole ? 0 : o.crop[1];
  const int W = whole ? cam.width : o.crop[2], H = whole ? cam.height : o.crop[3];
  if (o.film_in) {  // the earlier ranges' sums, continued (no second film allocated)
    if (!o.film_in->has_layout(X0, Y0, W, H, o.aovs))
      throw std::invalid_argument("render option 'film' does not cover this window with these AOVs");
    out.film = std::move(*o.film_in);
  } else {
    out.film.resize(X0, Y0, W, H, o.aovs);
  }
  out.num_columns = track_columns<M>();

  // Recorded pixels: slot per pixel of the window (-1 = not recorded).
  std::vector<int> slot(size_t(W) * H, -1);
  std::vector<std::vector<RecordedSegment>> rec;
  for (size_t k = 0; k + 1 < o.record_pixels.size(); k += 2) {
    const int x = o.record_pixels[k] - X0, y = o.record_pixels[k + 1] - Y0;
    if (x < 0 || y < 0 || x >= W || y >= H) continue;
    if (slot[size_t(y) * W + x] < 0) {
      slot[size_t(y) * W + x] = int(rec.size());
      rec.emplace_back();
    }
  }

  const size_t npix = size_t(W) * H;
  const int64_t B = o.sample_begin, B1 = B + o.spp;
  const SampleMultiples mult = sample_multiples(o.edge_samples, o.detail_samples);
  const int64_t D = mult.detail, E = mult.edge;
  std::atomic<int64_t> done{0};
  int64_t total = int64_t(npix) * o.spp;
  // A stop is for good: poll can be asked for a stop after a pass's last chunk has started, when
  // parallel_for reports the pass complete, and the next pass must not run.
  bool stopped = false;
  const std::function<bool()> poll = o.poll ? std::function<bool()>([&]() {
    if (!stopped && !o.poll(done.load(), total)) stopped = true;
    return !stopped;
  })
                                            : std::function<bool()>();
  std::vector<int64_t> classes;
  RenderStats probes;  // the probe rays' segments, counted with the samples'
  const bool find_edges = E > 1 && probe_lights, find_details = D > 1;
  if (o.classes_given && (find_edges || find_details)) {
    int64_t last = -1;
    for (const int64_t c : o.classes) {
      const int64_t p = c / kPixelClasses, k = c % kPixelClasses;
      if (c < 0 || size_t(p) >= npix || p <= last || (k != kEdgePixel && k != kDetailPixel && k != kBrightEdgePixel))
        throw std::invalid_argument("render option 'pixel_classes' must hold ascending pixels of the window, "
                                    "4 x index + 1 (detail), 2 (edge) or 3 (bright edge)");
      last = p;
      classes.push_back(c);
    }
  } else if (find_edges || find_details) {
    bool cancelled = false;
    const std::vector<double> images = find_edges && light_images ? light_images(X0, Y0, W, H) : std::vector<double>();
    classes = pixel_classes<M, S>(m, o, X0, Y0, W, H, probe, find_edges, find_details, poll, cancelled, probes, images,
                                  bright_edge);
    if (cancelled || stopped) {
      out.completed = false;
      return out;
    }
  }
  // The pixels given k x o.spp samples, by k (the bright edge pixels, the edge pixels, then the detail pixels).
  struct Group {
    int64_t k;
    std::vector<size_t> pixels;
  };
  Group groups[3] = {{mult.bright_edge, {}}, {E, {}}, {D, {}}};
  for (const int64_t c : classes) {
    const int64_t k = c % kPixelClasses;
    groups[k == kBrightEdgePixel ? 0 : k == kEdgePixel ? 1 : 2].pixels.push_back(size_t(c / kPixelClasses));
  }
  out.edge_pixels = int64_t(groups[0].pixels.size() + groups[1].pixels.size());
  out.bright_edge_pixels = int64_t(groups[0].pixels.size());
  out.detail_pixels = int64_t(groups[2].pixels.size());
  out.pixel_classes = classes;

  // The pixels of the main passes: all of them in the first range (a pixel's first samples [0, B1) come with
  // everyone's, so an interrupted first range is a whole image); later, only the others, an edge or detail
  // pixel's range [k B, k B1) being all in its own passes.
  std::vector<size_t> main_pixels;
  const bool all_main = (B == 0 && !photon_pass) || classes.empty();
  if (!all_main) {
    main_pixels.reserve(npix - classes.size());
    for (size_t p = 0, e = 0; p < npix; ++p) {
      if (e < classes.size() && size_t(classes[e] / kPixelClasses) == p) ++e;
      else main_pixels.push_back(p);
    }
  }
  const size_t nmain = all_main ? npix : main_pixels.size();
  total = int64_t(nmain) * o.spp;

  // Progressive passes (1, 1, 2, 4, ... samples) so an interrupted render is a whole image; then each group's
  // further samples, doubling. With photons, photon pass by photon pass instead: pass j's main samples, then
  // each group's.
  struct Pass {
    int64_t s0, s1;
    const std::vector<size_t>* pixels;  // a group's, or null: the main pixels
    int64_t k;                          // the pixels' multiple of spp
  };
  std::vector<Pass> passes;
  for (const Group& g : groups)
    if (!g.pixels.empty())  // the group's own samples
      total += int64_t(g.pixels.size()) * (g.k * B1 - (B == 0 && !photon_pass ? B1 : g.k * B));
  if (photon_pass) {
    for (int64_t j = B; j < B1; ++j) {
      passes.push_back({j, j + 1, nullptr, 1});
      for (const Group& g : groups)
        if (!g.pixels.empty()) passes.push_back({g.k * j, g.k * (j + 1), &g.pixels, g.k});
    }
  } else {
    for (int64_t s0 = B, n = 1; s0 < B1; s0 += n, n = std::min<int64_t>(2 * n, 64))
      passes.push_back({s0, std::min(B1, s0 + n), nullptr, 1});
    for (const Group& g : groups) {
      if (g.pixels.empty()) continue;
      const int64_t s0 = B == 0 ? B1 : g.k * B, s1 = g.k * B1;
      for (int64_t s = s0, n = std::min<int64_t>(o.spp, 64); s < s1; s += n, n = std::min<int64_t>(2 * n, 64))
        passes.push_back({s, std::min(s1, s + n), &g.pixels, g.k});
    }
  }
  std::mutex stats_mutex;  // (a chunk's counts are added once it is done)
  out.stats = probes;
  constexpr size_t kChunk = 64;  // pixels per parallel task
  // parallel_for polls every 20 ms while a pass runs; passes shorter than that (photon passes of one sample on
  // a small image) poll between them instead, at the same rate, so progress moves and Ctrl-C stops the render.
  auto last_poll = std::chrono::steady_clock::now();
  for (const auto& pass : passes) {
    if (poll && std::chrono::steady_clock::now() - last_poll >= std::chrono::milliseconds(20)) {
      last_poll = std::chrono::steady_clock::now();
      if (!poll()) {
        out.completed = false;
        break;
      }
    }
    if (photon_pass && !photon_pass(pass.s0 / pass.k)) {
      out.completed = false;
      break;
    }
    const size_t nwork = pass.pixels ? pass.pixels->size() : nmain;
    const size_t nchunks = (nwork + kChunk - 1) / kChunk;
    auto body = [&](size_t c) {
      const size_t p0 = c * kChunk, p1 = std::min(nwork, p0 + kChunk);
      const size_t ns = size_t(pass.s1 - pass.s0), njobs = (p1 - p0) * ns;
      auto pixel = [&](size_t k) {
        const size_t i = p0 + k / ns;
        return pass.pixels ? (*pass.pixels)[i] : all_main ? i : main_pixels[i];
      };
      std::vector<SampleOut> outs(njobs);
      RenderStats st;
      auto make = [&](size_t k, SampleScheduler<M, S>* sched) {
        const size_t pix = pixel(k);
        // A recorded pixel's samples below o.record_samples are recorded (in any range).
        const int s = int(pass.s0 + int64_t(k % ns));
        return sample(X0 + int(pix % W), Y0 + int(pix / W), s, out.film, outs[k],
                      slot[pix] >= 0 && s < o.record_samples, st, sched);
      };
      run_samples<M, S>(m, o.batch, njobs, make);
      // Summed in (pixel, sample) order, whatever order the samples finished in.
      for (size_t k = 0; k < njobs; ++k) {
        const size_t pix = pixel(k);
        accumulate(out.film, pix, outs[k]);
        if (slot[pix] >= 0)
          for (auto& seg : outs[k].rec) rec[slot[pix]].push_back(std::move(seg));
      }
      done += int64_t(njobs);
      const std::lock_guard<std::mutex> lock(stats_mutex);
      out.stats.add(st);
    };
    if (!parallel_for(nchunks, o.threads, 1, body, poll) || stopped) {
      out.completed = false;
      break;
    }
  }
  for (auto& r : rec)
    for (auto& seg : r) out.recorded.push_back(std::move(seg));
  return out;
}

}  // namespace wv
