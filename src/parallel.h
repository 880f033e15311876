// A small parallel loop for kernels whose items are independent: no R API is
// touched off the main thread, and the main thread polls for interrupts.
#ifndef ALLANVAR_PARALLEL_H
#define ALLANVAR_PARALLEL_H

#include <Rcpp.h>
#include <atomic>
#include <thread>
#include <vector>

namespace allanvar {

inline void check_interrupt_fn(void*) { R_CheckUserInterrupt(); }

// TRUE when the user has asked to interrupt; safe to call (main thread only)
// without a longjmp through C++ frames.
inline bool interrupt_pending() {
  return R_ToplevelExec(check_interrupt_fn, nullptr) == FALSE;
}

// Calls f(i, worker) for every i in [0, n) on up to `threads` threads, the
// calling thread being worker 0. Items are handed out one at a time, so
// uneven items balance. Throws Rcpp's interrupt after all workers stop.
template <class F>
void parallel_for(R_xlen_t n, int threads, F f) {
  if (threads < 1) threads = 1;
  if (static_cast<R_xlen_t>(threads) > n) threads = static_cast<int>(n);
  std::atomic<R_xlen_t> next(0);
  std::atomic<bool> stop(false);
  auto worker = [&](int id) {
    for (;;) {
      if (stop.load(std::memory_order_relaxed)) return;
      const R_xlen_t i = next.fetch_add(1);
      if (i >= n) return;
      f(i, id);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker, t);
  // The main thread works too and checks for interrupts between items.
  for (;;) {
    if (interrupt_pending()) {
      stop = true;
      break;
    }
    const R_xlen_t i = next.fetch_add(1);
    if (i >= n) break;
    f(i, 0);
  }
  for (auto& th : pool) th.join();
  if (stop) throw Rcpp::internal::InterruptedException();
}

}  // namespace allanvar

#endif
