// Scheduling a render's samples onto SIMD lanes. A sample is a coroutine that co_awaits each geodesic it
// needs (Geodesic). In curved space the geodesics of many samples wait in a queue and step together in SIMD
// lanes (spacetime/ray_batch.h); with batch = false each is integrated on the spot. Samples' radiance is
// summed in (pixel, sample) order either way (render_loop.h), so the image is bit-identical with and
// without lanes and for any thread count.
#pragma once

#include <algorithm>
#include <coroutine>
#include <cstddef>
#include <deque>
#include <functional>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/parallel.h"
#include "core/task.h"
#include "spacetime/geodesic.h"
#include "spacetime/ray_batch.h"
#include "spacetime/track.h"

namespace wv {

// Geodesics waiting for a lane, in the order they were asked for.
template <class M, class S>
struct SampleScheduler {
  // Geodesics step in SIMD lanes in curved space (ray_batch.h), through the batch form of stepper S.
  static constexpr bool kLaned = kLanesFor<M>;
  using Batch = std::conditional_t<kLaned, BatchOf<S>, S>;
  using Job = LaneJob<M, Batch>;
  std::deque<Job*> queue;
};

// Runs samples make(k, scheduler) for k in [0, n): with lanes, as many at once as keep the lanes busy;
// otherwise one after another, each geodesic integrated as soon as it is asked for.
template <class M, class S, class Make>
void run_samples(const M& m, bool batch, size_t n, const Make& make) {
  using Scheduler = SampleScheduler<M, S>;
  using Batch = typename Scheduler::Batch;
  using Job = typename Scheduler::Job;
  constexpr bool kLaned = Scheduler::kLaned;
  if constexpr (kLaned) {
    if (batch) {
      Scheduler sched;
      std::vector<Task<void>> running;
      size_t next = 0;
      auto sweep = [&]() {
        for (size_t i = 0; i < running.size();) {
          if (!running[i].done()) {
            ++i;
            continue;
          }
          running[i].rethrow_if_failed();
          running[i] = std::move(running.back());
          running.pop_back();
        }
      };
      // A lane needs a geodesic: take the oldest waiting one, starting new samples until there is one.
      auto fill = [&](int) -> Job* {
        while (sched.queue.empty() && next < n) {
          sweep();
          Task<void> t = make(next++, &sched);
          t.start();
          if (t.done()) t.rethrow_if_failed();
          else running.push_back(std::move(t));
        }
        if (sched.queue.empty()) return nullptr;
        Job* job = sched.queue.front();
        sched.queue.pop_front();
        return job;
      };
      run_lanes<M, Batch>(m, fill, [](Job* job, int) { job->waiter.resume(); });
      sweep();
      return;
    }
  }
  for (size_t k = 0; k < n; ++k) {
    Task<void> t = make(k, nullptr);
    t.start();
    t.rethrow_if_failed();
  }
}

// Runs make(k, stats, scheduler) for k in [0, count) on `threads` workers: parallel tasks of `per_task`
// consecutive k, each task's samples interleaved in lanes by run_samples and counted in its own stats,
// task_stats[t] (resized to the number of tasks, so the caller adds them up in a fixed order; Stats may carry
// a task's own buffers too), and finish(t) called on the task's worker once its samples are done. poll as
// parallel_for's; false: cancelled.
template <class M, class S, class Stats, class Make>
bool run_tasks(const M& m, bool batch, int threads, size_t count, size_t per_task, std::vector<Stats>& task_stats,
               const Make& make, const std::function<bool()>& poll = {},
               const std::function<void(size_t)>& finish = {}) {
  const size_t ntasks = (count + per_task - 1) / per_task;
  task_stats.assign(ntasks, Stats{});
  auto body = [&](size_t t) {
    const size_t k0 = t * per_task, k1 = std::min(count, k0 + per_task);
    run_samples<M, S>(m, batch, k1 - k0,
                      [&](size_t k, SampleScheduler<M, S>* sched) { return make(k0 + k, task_stats[t], sched); });
    if (finish) finish(t);
  };
  return parallel_for(ntasks, threads, 1, body, poll);
}

struct NoLane {};

// One geodesic to integrate, as an awaitable: queued for a lane (sched non-null) or integrated at once.
template <class M, class S, class Surf>
struct Geodesic {
  using Scheduler = SampleScheduler<M, S>;
  using Batch = typename Scheduler::Batch;
  static constexpr bool kLaned = Scheduler::kLaned;

  const M& m;
  Scheduler* sched;
  double y[8];
  int sheet;
  const TraceOptions& o;
  Track* track;
  Surf surf;
  double first_step;  // GeodesicRay::begin's
  RayResult res;
  std::conditional_t<kLaned, LaneRay<M, Batch, Surf>, NoLane> lane;

  Geodesic(const M& metric, Scheduler* s, const double y0[8], int sh, const TraceOptions& opt, Track* tr, Surf sf,
           double first = 0.0)
      : m(metric), sched(s), sheet(sh), o(opt), track(tr), surf(std::move(sf)), first_step(first) {
    for (int i = 0; i < 8; ++i) y[i] = y0[i];
  }
  Geodesic(const Geodesic&) = delete;
  Geodesic& operator=(const Geodesic&) = delete;

  bool await_ready() {
    if constexpr (kLaned) {
      if (sched) return !lane.start(m, y, sheet, o, res, track, &surf, first_step);
    }
    integrate_ray<M, S, Surf>(m, y, sheet, o, res, track, &surf, first_step);
    return true;
  }
  void await_suspend(std::coroutine_handle<> h) {
    if constexpr (kLaned) {
      lane.waiter = h;
      sched->queue.push_back(&lane);
    }
  }
  RayResult await_resume() const { return res; }
};

}  // namespace wv
