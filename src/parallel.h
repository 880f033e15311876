// Threads and interrupts for the kernels.
//  * interrupted(): kernels call it every few milliseconds of work, from any
//    thread. On R's main thread it asks R (at most every 20 ms) whether the
//    user pressed Ctrl-C and raises the shared stop flag; on a worker it
//    only reads the flag. A kernel that sees TRUE returns early; its partial
//    result is thrown away by InterruptScope::finish().
//  * parallel_for(): runs independent items on up to `threads` threads. An
//    exception in any item (std::bad_alloc, ...) stops the others, and is
//    rethrown on the calling thread after every worker has been joined, so
//    it reaches R as an R error, never std::terminate().
// No R API is touched off the main thread.
#ifndef ALLANVAR_PARALLEL_H
#define ALLANVAR_PARALLEL_H

#include <Rcpp.h>
#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace allanvar {

inline void check_interrupt_fn(void*) { R_CheckUserInterrupt(); }

// TRUE when the user has asked to interrupt; safe to call (main thread only)
// without a longjmp through C++ frames.
inline bool interrupt_pending() {
  return R_ToplevelExec(check_interrupt_fn, nullptr) == FALSE;
}

struct InterruptState {
  std::atomic<bool> stop{false};
  std::chrono::steady_clock::time_point last;
};

inline InterruptState& interrupt_state() {
  static InterruptState s;
  return s;
}

// FALSE on R's main thread, TRUE on threads started by parallel_for().
inline bool& on_worker_thread() {
  static thread_local bool worker = false;
  return worker;
}

inline bool interrupted() {
  InterruptState& s = interrupt_state();
  if (s.stop.load(std::memory_order_relaxed)) return true;
  if (on_worker_thread()) return false;
  const auto now = std::chrono::steady_clock::now();
  if (now - s.last < std::chrono::milliseconds(20)) return false;
  s.last = now;
  if (interrupt_pending()) {
    s.stop.store(true);
    return true;
  }
  return false;
}

// At the top of an entry point: clears the stop flag; finish() turns a stop
// into R's interrupt once the kernels have returned.
class InterruptScope {
 public:
  InterruptScope() {
    interrupt_state().stop.store(false);
    interrupt_state().last = std::chrono::steady_clock::now();
  }
  void finish() const {
    if (interrupt_state().stop.load()) {
      interrupt_state().stop.store(false);
      throw Rcpp::internal::InterruptedException();
    }
  }
};

// Calls f(i, worker) for every i in [0, n) on up to `threads` threads, the
// calling thread being worker 0. Items are handed out one at a time, so
// uneven items balance. Stops early on an interrupt or an exception; after
// all workers are joined, the exception is rethrown or R's interrupt raised
// (and the stop flag cleared).
template <class F>
void parallel_for(R_xlen_t n, int threads, F f) {
  if (threads < 1) threads = 1;
  if (static_cast<R_xlen_t>(threads) > n) threads = static_cast<int>(n);
  std::atomic<R_xlen_t> next(0);
  std::atomic<bool> failed(false);
  std::exception_ptr error;
  std::mutex error_mutex;
  auto fail = [&]() {
    std::lock_guard<std::mutex> lock(error_mutex);
    if (!error) error = std::current_exception();
    failed = true;
    interrupt_state().stop.store(true);  // long items elsewhere stop early
  };
  auto worker = [&](int id) {
    on_worker_thread() = true;
    try {
      for (;;) {
        if (failed.load(std::memory_order_relaxed) || interrupted()) return;
        const R_xlen_t i = next.fetch_add(1);
        if (i >= n) return;
        f(i, id);
      }
    } catch (...) {
      fail();
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) {
    try {
      pool.emplace_back(worker, t);
    } catch (...) {
      break;  // no thread to be had: the others (and this one) do the work
    }
  }
  // The main thread works too and checks for interrupts between items.
  try {
    for (;;) {
      if (failed.load(std::memory_order_relaxed) || interrupted()) break;
      const R_xlen_t i = next.fetch_add(1);
      if (i >= n) break;
      f(i, 0);
    }
  } catch (...) {
    fail();
  }
  for (auto& th : pool) th.join();
  const bool stopped = interrupt_state().stop.exchange(false);
  if (error) std::rethrow_exception(error);
  if (stopped) throw Rcpp::internal::InterruptedException();
}

}  // namespace allanvar

#endif
