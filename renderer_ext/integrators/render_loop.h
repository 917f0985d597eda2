// The render loop: progressive passes (1, 1, 2, 4, ... samples per pixel, so an interrupted render is a
// whole image) over chunks of pixels in parallel, then further samples in the pixels on the edge of a
// light seen directly or in mirrors and glass (found first, by probe rays on a fixed lattice), progress
// and cancellation, and the film's accumulation of what the samples add, in (pixel, sample) order
// whatever order they finished in; the recorded pixels' segments and the segment statistics are collected
// on the way.
#pragma once

#include <algorithm>
#include <atomic>
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

// The pixels of window (X0, Y0, W, H) whose footprint straddles the edge of a light, seen directly or in
// mirrors and glass, found without random numbers: probe(x, y, stats, scheduler, hit) gives a signature of
// the specular branches of the camera ray through image point (x, y) (pixel units) that end on an emitter
// (0: none), or -1 where some branches do and some do not (path_tracer.h); the probes lie on the lattice of
// half-pixel spacing (corners, edge midpoints and centres, shared by neighbours), and a pixel whose nine
// lattice points disagree, or one of which is -1, is an edge pixel. Depends only on the scene and the
// pixel, so every window agrees on it.
template <class M, class S, class Probe>
std::vector<size_t> edge_pixels(const M& m, const RenderOptions& o, int X0, int Y0, int W, int H, const Probe& probe,
                                const std::function<bool()>& poll, bool& cancelled, RenderStats& stats) {
  const size_t LW = size_t(2 * W + 1), LH = size_t(2 * H + 1), n = LW * LH;
  std::vector<int32_t> hit(n, 0);
  constexpr size_t kChunk = 256;  // lattice points per parallel task
  std::mutex stats_mutex;
  auto body = [&](size_t c) {
    const size_t k0 = c * kChunk, k1 = std::min(n, k0 + kChunk);
    RenderStats st;
    auto make = [&](size_t k, SampleScheduler<M, S>* sched) {
      const size_t i = k0 + k;
      return probe(X0 + 0.5 * double(i % LW), Y0 + 0.5 * double(i / LW), st, sched, hit[i]);
    };
    run_samples<M, S>(m, o.batch, k1 - k0, make);
    const std::lock_guard<std::mutex> lock(stats_mutex);
    for (int k = 0; k < 6; ++k) stats.counts[k] += st.counts[k];
    stats.steps += st.steps;
    stats.segments += st.segments;
  };
  cancelled = !parallel_for((n + kChunk - 1) / kChunk, o.threads, 1, body, poll);
  std::vector<size_t> edges;
  if (cancelled) return edges;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const int32_t h0 = hit[size_t(2 * y) * LW + size_t(2 * x)];
      bool edge = h0 < 0;
      for (int j = 0; j < 3 && !edge; ++j)
        for (int i = 0; i < 3; ++i) {
          const int32_t h = hit[size_t(2 * y + j) * LW + size_t(2 * x + i)];
          if (h != h0) edge = true;  // (h0 >= 0 here, so a mixed point differs)
        }
      if (edge) edges.push_back(size_t(y) * W + x);
    }
  return edges;
}

// Renders camera `cam` (its window o.crop, if set): samples [B, B + o.spp) of every pixel, B = o.sample_begin,
// and [E B, E (B + o.spp)) of each edge pixel (a light's edge, seen directly or in mirrors and glass),
// E = o.edge_samples (edge_pixels, probed before any sample where probe_edges, i.e. something emits, unless
// o.edges_given: the count does not depend on what the samples find, so every pixel's mean stays unbiased).
// Consecutive ranges therefore hold exactly the samples of one render of their total: a render can stop after
// any range and resume later. sample(px, py, s, film, out, recorded, stats, scheduler) is sample s of image
// pixel (px, py) as a Task (PathTracer::sample_pixel), run by run_samples. A pixel's samples do not depend on
// the window, so windows of an image tile it exactly.
template <class M, class S, class Sample, class Probe>
RenderResult render_passes(const M& m, const Camera& cam, const RenderOptions& o, const Sample& sample,
                           const Probe& probe, bool probe_edges) {
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
  const int64_t B = o.sample_begin, B1 = B + o.spp, E = o.edge_samples;
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
  std::vector<size_t> edges;
  RenderStats probes;  // the probe rays' segments, counted with the samples'
  if (E > 1 && o.edges_given) {
    edges.reserve(o.edges.size());
    for (const int64_t p : o.edges) {
      if (p < 0 || size_t(p) >= npix || (!edges.empty() && size_t(p) <= edges.back()))
        throw std::invalid_argument("render option 'edge_list' must hold ascending pixel indices of the window");
      edges.push_back(size_t(p));
    }
  } else if (E > 1 && probe_edges) {
    bool cancelled = false;
    edges = edge_pixels<M, S>(m, o, X0, Y0, W, H, probe, poll, cancelled, probes);
    if (cancelled || stopped) {
      out.completed = false;
      return out;
    }
  }
  out.edge_pixels = int64_t(edges.size());
  out.edge_list.assign(edges.begin(), edges.end());

  // The pixels of the main passes: all of them in the first range (an edge pixel's first samples [0, B1)
  // come with everyone's, so an interrupted first range is a whole image); later, only the others, an edge
  // pixel's range [E B, E B1) being all in its own passes.
  std::vector<size_t> main_pixels;
  const bool all_main = B == 0 || edges.empty();
  if (!all_main) {
    main_pixels.reserve(npix - edges.size());
    for (size_t p = 0, e = 0; p < npix; ++p) {
      if (e < edges.size() && edges[e] == p) ++e;
      else main_pixels.push_back(p);
    }
  }
  const size_t nmain = all_main ? npix : main_pixels.size();
  const int64_t edge_s0 = B == 0 ? B1 : E * B, edge_s1 = E * B1;  // the edge pixels' own samples
  total = int64_t(nmain) * o.spp + (edges.empty() ? 0 : int64_t(edges.size()) * (edge_s1 - edge_s0));

  // Progressive passes (1, 1, 2, 4, ... samples) so an interrupted render is a whole image; then the edge
  // pixels' further samples, doubling.
  struct Pass {
    int64_t s0, s1;
    bool edges_only;
  };
  std::vector<Pass> passes;
  for (int64_t s0 = B, n = 1; s0 < B1; s0 += n, n = std::min<int64_t>(2 * n, 64))
    passes.push_back({s0, std::min(B1, s0 + n), false});
  if (!edges.empty()) {
    for (int64_t s0 = edge_s0, n = std::min<int64_t>(o.spp, 64); s0 < edge_s1;
         s0 += n, n = std::min<int64_t>(2 * n, 64))
      passes.push_back({s0, std::min(edge_s1, s0 + n), true});
  }
  std::atomic<int64_t> counts[6];
  for (int k = 0; k < 6; ++k) counts[k] = probes.counts[k];
  std::atomic<int64_t> steps{probes.steps}, segments{probes.segments};
  constexpr size_t kChunk = 64;  // pixels per parallel task
  for (const auto& pass : passes) {
    const size_t nwork = pass.edges_only ? edges.size() : nmain;
    const size_t nchunks = (nwork + kChunk - 1) / kChunk;
    auto body = [&](size_t c) {
      const size_t p0 = c * kChunk, p1 = std::min(nwork, p0 + kChunk);
      const size_t ns = size_t(pass.s1 - pass.s0), njobs = (p1 - p0) * ns;
      auto pixel = [&](size_t k) {
        const size_t i = p0 + k / ns;
        return pass.edges_only ? edges[i] : all_main ? i : main_pixels[i];
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
      for (int k = 0; k < 6; ++k)
        if (st.counts[k]) counts[k] += st.counts[k];
      steps += st.steps;
      segments += st.segments;
    };
    if (!parallel_for(nchunks, o.threads, 1, body, poll) || stopped) {
      out.completed = false;
      break;
    }
  }
  for (int k = 0; k < 6; ++k) out.status_counts[k] = counts[k].load();
  out.total_steps = steps.load();
  out.segments = segments.load();
  for (auto& r : rec)
    for (auto& seg : r) out.recorded.push_back(std::move(seg));
  return out;
}

}  // namespace wv
