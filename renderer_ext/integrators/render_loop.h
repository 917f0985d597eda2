// The render loop: progressive passes (1, 1, 2, 4, ... samples per pixel, so an interrupted render is a
// whole image) over chunks of pixels in parallel, progress and cancellation, and the film's accumulation of
// what the samples add, in (pixel, sample) order whatever order they finished in; the recorded pixels'
// segments and the segment statistics are collected on the way.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
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
  std::vector<RecordedSegment> rec;  // recorded pixels: this sample's segments
};

// Adds one sample to its pixel.
inline void accumulate(Film& film, size_t pix, const SampleOut& so) {
  for (int c = 0; c < 3; ++c) film.rgb_sum[3 * pix + c] += so.L[c];
  film.samples[pix] += 1;
  if (!film.steps_sum.empty()) film.steps_sum[pix] += double(so.steps);
  if (!film.max_drift.empty()) film.max_drift[pix] = std::max(film.max_drift[pix], float(so.max_drift));
  if (so.error) film.errors[pix] += 1;
  if (!film.albedo_sum.empty())
    for (int c = 0; c < 3; ++c) film.albedo_sum[3 * pix + c] += so.albedo[c];
  if (!film.albedo_normal_sum.empty())
    for (int c = 0; c < 3; ++c) film.albedo_normal_sum[3 * pix + c] += so.albedo_normal[c];
}

// Renders camera `cam` (its window o.crop, if set) with o.spp samples per pixel: sample(px, py, s, film, out,
// recorded, stats, scheduler) is sample s of image pixel (px, py) as a Task (PathTracer::sample_pixel), run
// by run_samples. A pixel's samples do not depend on the window, so windows of an image tile it exactly.
template <class M, class S, class Sample>
RenderResult render_passes(const M& m, const Camera& cam, const RenderOptions& o, const Sample& sample) {
  RenderResult out;
  const bool whole = o.crop[2] <= 0 || o.crop[3] <= 0;
  const int X0 = whole ? 0 : o.crop[0], Y0 = whole ? 0 : o.crop[1];
  const int W = whole ? cam.width : o.crop[2], H = whole ? cam.height : o.crop[3];
  out.film.resize(X0, Y0, W, H, o.aovs);
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

  // Progressive passes (1, 1, 2, 4, ... samples) so an interrupted render is a whole image.
  std::vector<std::pair<int, int>> passes;
  for (int s0 = 0, n = 1; s0 < o.spp; s0 += n, n = std::min(2 * n, 64))
    passes.emplace_back(s0, std::min(o.spp, s0 + n));
  const int64_t total = int64_t(W) * H * o.spp;
  std::atomic<int64_t> done{0};
  std::atomic<int64_t> counts[6];
  for (auto& c : counts) c = 0;
  std::atomic<int64_t> steps{0}, segments{0};
  // A stop is for good: poll can be asked for a stop after a pass's last chunk has started, when
  // parallel_for reports the pass complete, and the next pass must not run.
  bool stopped = false;
  const std::function<bool()> poll = o.poll ? std::function<bool()>([&]() {
    if (!stopped && !o.poll(done.load(), total)) stopped = true;
    return !stopped;
  })
                                            : std::function<bool()>();
  const size_t npix = size_t(W) * H;
  constexpr size_t kChunk = 64;  // pixels per parallel task
  const size_t nchunks = (npix + kChunk - 1) / kChunk;
  for (const auto& pass : passes) {
    auto body = [&](size_t c) {
      const size_t p0 = c * kChunk, p1 = std::min(npix, p0 + kChunk);
      const size_t ns = size_t(pass.second - pass.first), njobs = (p1 - p0) * ns;
      std::vector<SampleOut> outs(njobs);
      RenderStats st;
      auto make = [&](size_t k, SampleScheduler<M, S>* sched) {
        const size_t pix = p0 + k / ns;
        return sample(X0 + int(pix % W), Y0 + int(pix / W), pass.first + int(k % ns), out.film, outs[k],
                      slot[pix] >= 0, st, sched);
      };
      run_samples<M, S>(m, o.batch, njobs, make);
      // Summed in (pixel, sample) order, whatever order the samples finished in.
      for (size_t k = 0; k < njobs; ++k) {
        const size_t pix = p0 + k / ns;
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
