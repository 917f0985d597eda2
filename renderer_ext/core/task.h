// A minimal lazy coroutine task (C++20), so a light path can be written as straight-line code that
// `co_await`s each geodesic it needs while a scheduler steps many paths' geodesics together in SIMD lanes
// (integrators/sample_scheduler.h, spacetime/ray_batch.h).
//
//   Task<int> f() { co_return 1; }
//   Task<void> g() { int x = co_await f(); ... }
//
// A task starts when awaited (or when resume() is called on the outermost one) and, when it finishes,
// continues the coroutine that awaited it. Exceptions propagate to the awaiter (or to rethrow_if_failed()).
#pragma once

#include <coroutine>
#include <cstddef>
#include <new>
#include <exception>
#include <type_traits>
#include <utility>

namespace wv {

template <class T>
class Task;

namespace detail {

// Coroutine frames come from a per-thread free list per 64-byte size class, so the coroutines of a path
// (one per sample and segment) cost no malloc once the lists are warm. Frames above 16 KiB use the heap.
class FramePool {
 public:
  FramePool() = default;
  FramePool(const FramePool&) = delete;
  FramePool& operator=(const FramePool&) = delete;
  ~FramePool() {
    for (Node*& head : free_)
      while (head) {
        Node* next = head->next;
        ::operator delete(head);
        head = next;
      }
  }
  void* allocate(std::size_t n) {
    const std::size_t c = size_class(n);
    if (c >= kClasses) return ::operator new(n);
    if (Node* head = free_[c]) {
      free_[c] = head->next;
      return head;
    }
    return ::operator new(c * kClassBytes);
  }
  void release(void* p, std::size_t n) noexcept {
    const std::size_t c = size_class(n);
    if (c >= kClasses) {
      ::operator delete(p);
      return;
    }
    Node* node = static_cast<Node*>(p);
    node->next = free_[c];
    free_[c] = node;
  }

 private:
  static constexpr std::size_t kClassBytes = 64, kClasses = 256;
  static std::size_t size_class(std::size_t n) { return (n + kClassBytes - 1) / kClassBytes; }
  struct Node {
    Node* next;
  };
  Node* free_[kClasses] = {};
};

inline FramePool& frame_pool() {
  thread_local FramePool pool;
  return pool;
}

struct TaskPromiseBase {
  std::coroutine_handle<> continuation;
  std::exception_ptr error;

  static void* operator new(std::size_t n) { return frame_pool().allocate(n); }
  static void operator delete(void* p, std::size_t n) noexcept { frame_pool().release(p, n); }

  std::suspend_always initial_suspend() noexcept { return {}; }
  struct FinalAwaiter {
    bool await_ready() noexcept { return false; }
    template <class P>
    std::coroutine_handle<> await_suspend(std::coroutine_handle<P> h) noexcept {
      auto c = h.promise().continuation;
      return c ? c : std::noop_coroutine();
    }
    void await_resume() noexcept {}
  };
  FinalAwaiter final_suspend() noexcept { return {}; }
  void unhandled_exception() { error = std::current_exception(); }
};

template <class T>
struct TaskPromise : TaskPromiseBase {
  T value{};
  Task<T> get_return_object();
  void return_value(T v) { value = std::move(v); }
};

template <>
struct TaskPromise<void> : TaskPromiseBase {
  Task<void> get_return_object();
  void return_void() {}
};

}  // namespace detail

template <class T>
class [[nodiscard]] Task {
 public:
  using promise_type = detail::TaskPromise<T>;
  using Handle = std::coroutine_handle<promise_type>;

  Task() = default;
  explicit Task(Handle h) : h_(h) {}
  Task(Task&& o) noexcept : h_(std::exchange(o.h_, {})) {}
  Task& operator=(Task&& o) noexcept {
    if (this != &o) {
      if (h_) h_.destroy();
      h_ = std::exchange(o.h_, {});
    }
    return *this;
  }
  Task(const Task&) = delete;
  Task& operator=(const Task&) = delete;
  ~Task() {
    if (h_) h_.destroy();
  }

  // Awaiting a task runs it; the awaiter continues when it finishes.
  bool await_ready() const noexcept { return false; }
  std::coroutine_handle<> await_suspend(std::coroutine_handle<> awaiter) noexcept {
    h_.promise().continuation = awaiter;
    return h_;
  }
  T await_resume() {
    if (h_.promise().error) std::rethrow_exception(h_.promise().error);
    if constexpr (!std::is_void_v<T>) return std::move(h_.promise().value);
  }

  // Outermost task: start it (it runs until its first suspension), then ask whether it has finished.
  void start() { h_.resume(); }
  bool done() const { return h_.done(); }
  void rethrow_if_failed() const {
    if (h_.promise().error) std::rethrow_exception(h_.promise().error);
  }

 private:
  Handle h_{};
};

namespace detail {
template <class T>
Task<T> TaskPromise<T>::get_return_object() {
  return Task<T>(std::coroutine_handle<TaskPromise<T>>::from_promise(*this));
}
inline Task<void> TaskPromise<void>::get_return_object() {
  return Task<void>(std::coroutine_handle<TaskPromise<void>>::from_promise(*this));
}
}  // namespace detail

}  // namespace wv
