// Path guiding's training (guide_tree.h): before a render's first sample, iterations of 1, 2, 4, ...,
// o.guide_training samples at each point of a grid of at most kGuideGridWidth columns, and at most half the
// image's, over the camera's whole image (a fixed cost: under 1 % of a 640 x 480 x 16 frame; a thumbnail's
// grid is coarser so that it stays small there too). Iteration k's paths draw their directions from
// iteration k - 1's tree (the first: BSDF only) and record, at each diffuse vertex, the direction they left
// along and what came back, and what each light sample brought (path_tracer.h); the records, in (grid
// point, sample) order, build iteration k's tree, and the last tree is the render's guide.
//
// The training paths draw their own random numbers (a seed derived from the render's and the iteration's),
// and which paths run depends only on the camera and the options, never on the render's window or range: so
// every tile and every resumed range of an image trains the same tree, bit for bit on any number of threads,
// and the render's samples, independent of the tree's randomness, stay unbiased whatever the tree is.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <vector>

#include "core/parallel.h"
#include "film/film.h"
#include "integrators/guide_tree.h"
#include "integrators/render_loop.h"
#include "integrators/render_types.h"
#include "integrators/sample_scheduler.h"
#include "scene/scene.h"

namespace wv {

inline constexpr int kGuideGridWidth = 64;

// The seed of training iteration k's paths (a 64-bit mix of the render's seed and k).
inline uint64_t guide_seed(uint64_t seed, int k) {
  uint64_t z = seed ^ (0x9e3779b97f4a7c15ull * uint64_t(k + 1)) ^ 0x6a09e667f3bcc909ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// Trains `tree` for camera cam and a scene of `lights` lights. make(prev, seed) gives the iteration's tracer
// (a pointer-like object whose sample_pixel(px, py, s, film, out, recorded, stats, scheduler) records into
// out.guide), sampling with tree prev (null: none); poll() false stops the training (the tree is then left
// empty). Returns the training's segment statistics in `stats`.
template <class M, class S, class Make>
void train_guide(const M& m, const Camera& cam, const RenderOptions& o, const Box& bounds, int lights, const Make& make,
                 const std::function<bool()>& poll, GuideTree& tree, RenderStats& stats) {
  tree = GuideTree();
  if (o.guide_training <= 0) return;
  const int gw = std::clamp(cam.width / 2, 1, kGuideGridWidth);  // (a thumbnail: a point per 2 x 2 pixels)
  const int gh = std::clamp(int(std::lround(double(gw) * cam.height / cam.width)), 1, cam.height);
  const size_t npts = size_t(gw) * gh;
  Film none;  // (no AOVs: a training sample writes nothing to a film)
  GuideTree prev;
  for (int k = 0, spp = 1; spp <= o.guide_training; ++k, spp *= 2) {
    const auto tracer = make(prev.empty() ? nullptr : &prev, guide_seed(o.seed, k));
    constexpr size_t kChunk = 16;  // grid points per parallel task
    const size_t nchunks = (npts + kChunk - 1) / kChunk;
    std::vector<std::vector<GuideRecord>> chunk_records(nchunks);
    std::vector<RenderStats> chunk_stats(nchunks);
    auto body = [&](size_t c) {
      const size_t p0 = c * kChunk, p1 = std::min(npts, p0 + kChunk), ns = size_t(spp), njobs = (p1 - p0) * ns;
      std::vector<SampleOut> outs(njobs);
      auto make_sample = [&](size_t j, SampleScheduler<M, S>* sched) {
        const size_t p = p0 + j / ns;
        const int px = int((2 * (p % gw) + 1) * size_t(cam.width) / (2 * size_t(gw)));
        const int py = int((2 * (p / gw) + 1) * size_t(cam.height) / (2 * size_t(gh)));
        return tracer->sample_pixel(px, py, int(j % ns), none, outs[j], false, chunk_stats[c], sched);
      };
      run_samples<M, S>(m, o.batch, njobs, make_sample);
      for (auto& so : outs)
        for (const GuideRecord& r : so.guide) chunk_records[c].push_back(r);
    };
    if (!parallel_for(nchunks, o.threads, 1, body, poll)) {
      tree = GuideTree();
      return;
    }
    std::vector<GuideRecord> records;
    for (auto& cr : chunk_records) records.insert(records.end(), cr.begin(), cr.end());
    for (const RenderStats& st : chunk_stats) {
      stats.segments += st.segments;
      stats.steps += st.steps;
    }
    GuideTree next;
    GuideTree::Params params;
    params.lights = lights;
    next.build(std::move(records), bounds, params);
    prev = std::move(next);
  }
  tree = std::move(prev);
}

}  // namespace wv
