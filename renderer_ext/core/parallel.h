// A minimal deterministic parallel loop: items are independent, so results never depend on the
// number of threads or on which thread ran which chunk.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace wv {

inline int resolve_threads(int requested) {
  if (requested > 0) return requested;
  const unsigned hc = std::thread::hardware_concurrency();
  return hc > 0 ? int(hc) : 1;
}

// Runs body(i) for i in [0, n) on `threads` workers in chunks. While they run, the calling thread calls
// poll() every ~20 ms and returns as soon as they finish; poll returning false cancels the remaining
// chunks (e.g. Ctrl-C in Python).
// Returns false if cancelled. Exceptions from body are rethrown on the calling thread.
inline bool parallel_for(std::size_t n, int threads, std::size_t chunk, const std::function<void(std::size_t)>& body,
                         const std::function<bool()>& poll = {}) {
  threads = std::max(1, std::min<int>(resolve_threads(threads), int((n + chunk - 1) / std::max<std::size_t>(chunk, 1))));
  std::atomic<std::size_t> next{0};
  std::atomic<bool> cancel{false};
  std::atomic<int> running{threads};
  std::exception_ptr error;
  std::mutex error_mutex;
  std::mutex done_mutex;
  std::condition_variable done;
  auto worker = [&]() {
    try {
      while (!cancel.load(std::memory_order_relaxed)) {
        const std::size_t start = next.fetch_add(chunk);
        if (start >= n) break;
        const std::size_t end = std::min(n, start + chunk);
        for (std::size_t i = start; i < end; ++i) body(i);
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      cancel = true;
    }
    {
      std::lock_guard<std::mutex> lock(done_mutex);
      running.fetch_sub(1);
    }
    done.notify_all();
  };
  std::vector<std::thread> pool;
  if (!poll && threads == 1) {
    worker();
  } else {
    for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
    // Poll every 20 ms, but return as soon as the workers are done (no sleep floor on short calls).
    while (poll) {
      {
        std::unique_lock<std::mutex> lock(done_mutex);
        if (done.wait_for(lock, std::chrono::milliseconds(20), [&] { return running.load() == 0; })) break;
      }
      if (!cancel.load() && !poll()) cancel = true;
    }
    for (auto& th : pool) th.join();
  }
  if (error) std::rethrow_exception(error);
  return !cancel.load() || next.load() >= n;
}

}  // namespace wv
