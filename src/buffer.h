// A large uninitialised double (or float) buffer shared by the estimator kernels
// (src/allan.cpp, src/dynamic.cpp). On Linux it is 2 MiB aligned and marked
// for transparent huge pages: a fresh 100 MB prefix array otherwise costs
// tens of thousands of page faults, more than the sums themselves. Large
// buffers are kept when freed and handed to the next one that fits (two,
// 320 MiB in all: one call's prefix arrays at 1e7): the system zeroes
// every fresh page, which took 50 ms of 250 per overlapping AV of 1e7
// samples; the price is memory held between calls.
#ifndef ALLANVAR_BUFFER_H
#define ALLANVAR_BUFFER_H

#include <Rcpp.h>
#include <cstdlib>
#include <mutex>
#include <new>
#include <utility>
#include <vector>
#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace allanvar {

// Freed buffers of at least 2 MiB and at most 256 MiB, for requests they
// fit at most twice over (best fit); the oldest dropped beyond two or
// 320 MiB; any thread.
class BufferPool {
 public:
  ~BufferPool() {
    for (auto& b : blocks_) std::free(b.first);
  }
  // a kept block of at least `bytes` (and its size), else nullptr
  void* take(size_t bytes, size_t& got) {
    if (bytes < kMin || bytes > kMax) return nullptr;
    std::lock_guard<std::mutex> lock(mu_);
    size_t best = blocks_.size();
    for (size_t i = 0; i < blocks_.size(); ++i) {
      if (blocks_[i].second >= bytes && blocks_[i].second / 2 <= bytes &&
          (best == blocks_.size() || blocks_[i].second < blocks_[best].second))
        best = i;
    }
    if (best == blocks_.size()) return nullptr;
    void* p = blocks_[best].first;
    got = blocks_[best].second;
    held_ -= got;
    blocks_.erase(blocks_.begin() + best);
    return p;
  }
  void give(void* p, size_t bytes) {
    if (!p) return;
    if (bytes < kMin || bytes > kMax) {
      std::free(p);
      return;
    }
    std::lock_guard<std::mutex> lock(mu_);
    blocks_.emplace_back(p, bytes);
    held_ += bytes;
    while (blocks_.size() > 2 || held_ > kHeld) {
      std::free(blocks_.front().first);
      held_ -= blocks_.front().second;
      blocks_.erase(blocks_.begin());
    }
  }

 private:
  static const size_t kMin = static_cast<size_t>(1) << 21;
  static const size_t kMax = static_cast<size_t>(1) << 28;
  static const size_t kHeld = static_cast<size_t>(320) << 20;
  std::mutex mu_;
  std::vector<std::pair<void*, size_t>> blocks_;
  size_t held_ = 0;
};

inline BufferPool& buffer_pool() {
  static BufferPool p;
  return p;
}

template <class T>
class BasicBuffer {
 public:
  BasicBuffer() {}
  BasicBuffer(const BasicBuffer&) = delete;
  BasicBuffer& operator=(const BasicBuffer&) = delete;
  ~BasicBuffer() { buffer_pool().give(p_, bytes_); }
  void resize(R_xlen_t n) {
    buffer_pool().give(p_, bytes_);
    p_ = nullptr;
    bytes_ = 0;
    n_ = n;
    const size_t bytes = static_cast<size_t>(n > 0 ? n : 1) * sizeof(T);
    size_t got = 0;
    if (void* q = buffer_pool().take(bytes, got)) {
      p_ = static_cast<T*>(q);
      bytes_ = got;
      return;
    }
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    const size_t align = static_cast<size_t>(1) << 21;
    if (bytes >= align) {
      void* q = nullptr;
      if (posix_memalign(&q, align, bytes) == 0) {
        madvise(q, bytes, MADV_HUGEPAGE);
        p_ = static_cast<T*>(q);
      }
    }
#endif
    if (!p_) p_ = static_cast<T*>(std::malloc(bytes));
    if (!p_) throw std::bad_alloc();
    bytes_ = bytes;
  }
  T* data() { return p_; }
  const T* data() const { return p_; }
  T& operator[](R_xlen_t i) { return p_[i]; }
  const T& operator[](R_xlen_t i) const { return p_[i]; }
  R_xlen_t size() const { return n_; }

 private:
  T* p_ = nullptr;
  size_t bytes_ = 0;
  R_xlen_t n_ = 0;
};

using Buffer = BasicBuffer<double>;
using FloatBuffer = BasicBuffer<float>;

}  // namespace allanvar

#endif
